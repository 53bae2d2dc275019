"""Your own gripper, start to end: a 2-input 2-output record → FRF with σ →
state-space model (subspace + PEM) with σ → model file → simulate and compare on new data →
HTML report. Run: ``python examples/mimo_state_space.py [--figures DIR]``.

The "gripper" here is a known 4th-order plant (two valve currents a, b driving a fingertip force c
and a tip position d), so every number can be checked against the truth.
"""

import sys
import tempfile
from pathlib import Path

import numpy as np

from gripkit import Trajectory
from gripkit.io import save
from gripkit.excitation import periodic_multisine
from gripkit.lti import StateSpace
from gripkit.sysid import identify, load_model

rng = np.random.default_rng(3)
A = np.array([[0.9, 0.2, 0, 0], [-0.2, 0.9, 0, 0], [0, 0, 0.7, 0], [0, 0, 0, -0.4]])
T = rng.standard_normal((4, 4)) + 3 * np.eye(4)
plant = StateSpace(T @ A @ np.linalg.inv(T), rng.standard_normal((4, 2)),
                   rng.standard_normal((2, 4)), dt=0.01,
                   inputs=["a", "b"], outputs=["c", "d"], input_units=["A", "A"],
                   output_units=["N", "m"])


def record(u, seed):
    """The plant's response with 5 % output noise, around an operating point (0.85 A, 2 N)."""
    r = np.random.default_rng(seed)
    y = plant.simulate(u)
    y = y + 0.05 * y.std(axis=0) * r.standard_normal(y.shape)
    return Trajectory.uniform(dt=0.01, a=u[:, 0] + 0.85, b=u[:, 1] + 0.85, c=y[:, 0] + 2.0,
                              d=y[:, 1],
                              units={"a": "A", "b": "A", "c": "N", "d": "m"})


work = Path(tempfile.mkdtemp(prefix="gripkit-mimo-"))
# 1. excitation: independent random inputs on a and b (both drive the plant at every frequency;
#    one periodic multisine per input on the same lines would not separate the two inputs)
est = record(0.2 * rng.standard_normal((6000, 2)), seed=1)
val = record(0.2 * rng.standard_normal((4000, 2)), seed=2)
save(est, work / "est.csv")
save(val, work / "val.csv")
# a single-input periodic test: crest-factor-optimised multisine, 5 periods → FRF averaged over
# periods
ex = periodic_multisine(0.1, 45.0, 1000, 5, dt=0.01, amplitude=0.2)
siso = record(np.column_stack([ex.u, np.zeros_like(ex.u)]), seed=3)
rp = identify(siso, "frf", input="a", output="c", periods=5)
print(f"multisine crest factor {ex.crest_factor:.2f}; periodic FRF a→c: "
      f"{rp.frequency_hz.size} lines, "
      f"median σ/|H| = {np.median(rp.H_std[:, 0, 0] / np.abs(rp.H[:, 0, 0])):.2%}; data in {work}")

# 2. nonparametric first: H1 with σ and coherence (both inputs at once)
r = identify(est, "frf", input="a,b", output="c,d", nperseg=500)
print(f"FRF: {r.frequency_hz.size} lines, median coherence {np.nanmedian(r.coherence):.3f}")

# 3. state space: order from the singular values, subspace then PEM, validated on the second record
from gripkit.sysid.linear.identify_mimo import identify_ss  # noqa: E402

model, extras = identify_ss(est, input="a,b", output="c,d", validate=val)
p, cov = model.system.pole_covariance()
print(f"order {model.order} ({model.info['order_selection']}), validation fit "
      + ", ".join(f"{n} {f:.2f} %" for n, f in zip(model.outputs,
                                                   extras["validation_fit_percent"])))
for z, c in zip(p, cov):
    print(f"  pole {z.real:+.4f}{z.imag:+.4f}j  σ = ({np.sqrt(c[0, 0]):.1e}, "
          f"{np.sqrt(c[1, 1]):.1e})")

# 4. the model is a file: reload, simulate and compare on the validation record
model.save(work / "gripper.json")
back = load_model(work / "gripper.json")
fitted = back.compare(val)
fit, y_sim = fitted.fit_percent, fitted.simulated
print("reloaded model, free-run fit on validation data: " + ", ".join(f"{f:.2f} %" for f in fit))

# 5. the report
from gripkit.sysid.model_report import write_model_report  # noqa: E402

print(f"report: {write_model_report(back, val, work / 'report', data_name='val.csv')}")

if "--figures" in sys.argv:  # the pictures of docs/sysid.md
    from gripkit.sysid.model_report import bode_figure, singular_value_figure
    from gripkit.report.plots import measured_vs_model

    out = Path(sys.argv[sys.argv.index("--figures") + 1])
    singular_value_figure(np.asarray(model.singular_values),
                          model.order).savefig(out / "sysid-mimo-singular-values.png", dpi=90)
    bode_figure(model.system, 0.01, r).savefig(out / "sysid-mimo-bode.png", dpi=80)
    t = val.t[:600] - val.t[0]
    measured_vs_model(t, val["c"][:600], {"model (free run)": y_sim[:600, 0]}, ylabel="c [N]",
                      title="fingertip force c, "
                            "validation record").savefig(out / "sysid-mimo-validation.png", dpi=90)
    print(f"figures written to {out}")
