"""Code for the target: an identified linear model as a C99 step function.

:func:`export_c` writes ``NAME.h`` and ``NAME.c`` (no allocation, nothing beyond ``<math.h>``
and ``<string.h>``); :func:`c_sources` returns their text; :func:`c_harness` is a small program
that feeds a file of inputs through the step and prints the outputs (tests and users check the
export with it); :func:`float32_error_bound` is the a-priori bound of the ``--float32`` variant.
:func:`controller_c_sources` (PID, RST, LQR state feedback) and :func:`rls_c_sources` (the RLS
update) do the same for controllers, with :func:`controller_harness` and :func:`rls_harness`;
:func:`export_kalman_c` writes the model's steady-state Kalman filter (``NAME_kf_step``).
See docs/deploy.md."""

from ..exports import lazy_exports

_LAZY = {"export_c": ("c_code", "export_c"), "c_sources": ("c_code", "c_sources"),
         "c_harness": ("c_code", "c_harness"),
         "float32_error_bound": ("c_code", "float32_error_bound"),
         "check_c_name": ("c_code", "check_c_name"),
         "float32_bound_on": ("c_code", "float32_bound_on"),
         "controller_c_sources": ("c_controllers", "controller_c_sources"),
         "controller_harness": ("c_controllers", "controller_harness"),
         "export_controller_c": ("c_controllers", "export_controller_c"),
         "rls_c_sources": ("c_rls", "rls_c_sources"),
         "rls_harness": ("c_rls", "rls_harness"),
         "export_rls_c": ("c_rls", "export_rls_c"),
         "export_kalman_c": ("c_kalman", "export_kalman_c"),
         "kalman_c_sources": ("c_kalman", "kalman_c_sources"),
         "kalman_c_harness": ("c_kalman", "kalman_c_harness"),
         "kalman_filter_of": ("c_kalman", "kalman_filter_of")}
__all__ = [*_LAZY]
__getattr__, __dir__ = lazy_exports(__name__, _LAZY)
