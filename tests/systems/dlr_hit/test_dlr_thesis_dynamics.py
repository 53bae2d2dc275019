"""The finger's dynamics reproduce the thesis's printed symbolic terms (``002_ddea254371185ad3.txt``
Appendix F, M1; Appendix B/F, C_2 and C_3) when set up as the thesis does: centres of mass on the
link axes at lc = |pc|, thin-rod link inertia I_C = diag(0, m·lc², m·lc²) (the inertia tensors
the printed M1 implies), θ4 = θ3 with τ4 added to τ3, rotor inertia Im·N² on joint 1."""

import math

import numpy as np
import pytest
from numpy import cos, sin

from gripkit.multibody import CoupledChain, Coupling, DHChain
from gripkit.systems.dlr_hit.parameters import finger, thesis_finger_parameters

P = thesis_finger_parameters().value
L1, L2 = P("l1"), P("l2")
M1_, M2_, M3_ = P("m1"), P("m2"), P("m3")
LC = [math.sqrt(sum(P(f"pc{k}_{a}") ** 2 for a in "xyz")) for k in (1, 2, 3)]
IM = 5.1e-7
N1 = 100 * 2.083 * 1.125


def thesis_chain(alpha1):
    rod = [np.diag([0.0, m * lc * lc, m * lc * lc]) for m, lc in zip((M1_, M2_, M3_), LC)]
    ch = DHChain(alpha=[0, alpha1, 0, 0], a=[0, 0, L1, L2], d=np.zeros(4), mass=[0, M1_, M2_, M3_],
                 com=[[0, 0, 0], [LC[0], 0, 0], [LC[1], 0, 0], [LC[2], 0, 0]],
                 inertia=np.array([np.zeros((3, 3)), *rod]), gravity=(0, 0, 0))
    G = np.array([[1, 0, 0], [0, 1, 0], [0, 0, 1], [0, 0, 1.0]])  # θ4 = θ3, τ3 += τ4 (§4.5)
    return (CoupledChain(ch, Coupling(G, np.zeros(4), np.array([IM * N1 ** 2, 0, 0]),
                                      ("t1", "t2", "t3"))))


def appendix_f_M1(t2, t3):
    l1, l2, m1, m2, m3 = L1, L2, M1_, M2_, M3_
    l1c, l2c, l3c = LC
    return (IM * N1 ** 2 + (l2 ** 2 * m3) / 2 + l2c ** 2 * m2 + l3c ** 2 * m3
            + (l2 ** 2 * m3 * cos(2 * t2 + 2 * t3)) / 2 + l2c ** 2 * m2 * cos(2 * t2 + 2 * t3)
            + l3c ** 2 * m3 * cos(2 * t2 + 4 * t3) + l1 ** 2 * m2 * cos(t2) ** 2 + l1 ** 2 * m3
            * cos(t2) ** 2
            + 2 * l1c ** 2 * m1 * cos(t2) ** 2 + l1 * l3c * m3 * cos(2 * t2 + 2 * t3)
            + l2 * l3c * m3 * cos(2 * t2 + 3 * t3) + l1 * l2 * m3 * cos(t3) + l1 * l2c * m2
            * cos(t3)
            + l2 * l3c * m3 * cos(t3) + l1 * l2 * m3 * cos(2 * t2 + t3) + l1 * l2c * m2
            * cos(2 * t2 + t3)
            + l1 * l3c * m3 * cos(2 * t3))


def appendix_b_C(t2, t3, td1, td2, td3):
    l1, l2, m1, m2, m3 = L1, L2, M1_, M2_, M3_
    l1c, l2c, l3c = LC
    C2 = ((l1 ** 2 * m2 * td1 ** 2 * sin(2 * t2)) / 2 + (l1 ** 2 * m3 * td1 ** 2 * sin(2 * t2)) / 2
          + l1c ** 2 * m1 * td1 ** 2 * sin(2 * t2)
          + (l2 ** 2 * m3 * td1 ** 2 * sin(2 * t2 + 2 * t3)) / 2
          + l2c ** 2 * m2 * td1 ** 2 * sin(2 * t2 + 2 * t3) + l3c ** 2 * m3 * td1 ** 2
          * sin(2 * t2 + 4 * t3)
          - l1 * l2 * m3 * td3 ** 2 * sin(t3) - l1 * l2c * m2 * td3 ** 2 * sin(t3)
          - 3 * l2 * l3c * m3 * td3 ** 2 * sin(t3) + l1 * l2 * m3 * td1 ** 2 * sin(2 * t2 + t3)
          + l1 * l2c * m2 * td1 ** 2 * sin(2 * t2 + t3) - 4 * l1 * l3c * m3 * td3 ** 2 * sin(2 * t3)
          + l1 * l3c * m3 * td1 ** 2 * sin(2 * t2 + 2 * t3) + l2 * l3c * m3 * td1 ** 2
          * sin(2 * t2 + 3 * t3)
          - 2 * l1 * l2 * m3 * td2 * td3 * sin(t3) - 2 * l1 * l2c * m2 * td2 * td3 * sin(t3)
          - 2 * l2 * l3c * m3 * td2 * td3 * sin(t3) - 4 * l1 * l3c * m3 * td2 * td3 * sin(2 * t3))
    C3 = ((l2 ** 2 * m3 * td1 ** 2 * sin(2 * t2 + 2 * t3)) / 2 + l2c ** 2 * m2 * td1 ** 2
          * sin(2 * t2 + 2 * t3)
          + 2 * l3c ** 2 * m3 * td1 ** 2 * sin(2 * t2 + 4 * t3)
          + (l1 * l2 * m3 * td1 ** 2 * sin(t3)) / 2
          + l1 * l2 * m3 * td2 ** 2 * sin(t3) + (l1 * l2c * m2 * td1 ** 2 * sin(t3)) / 2
          + l1 * l2c * m2 * td2 ** 2 * sin(t3) + (l2 * l3c * m3 * td1 ** 2 * sin(t3)) / 2
          + l2 * l3c * m3 * td2 ** 2 * sin(t3) - 2 * l2 * l3c * m3 * td3 ** 2 * sin(t3)
          + (l1 * l2 * m3 * td1 ** 2 * sin(2 * t2 + t3)) / 2
          + (l1 * l2c * m2 * td1 ** 2 * sin(2 * t2 + t3)) / 2
          + l1 * l3c * m3 * td1 ** 2 * sin(2 * t3) + 2 * l1 * l3c * m3 * td2 ** 2 * sin(2 * t3)
          + l1 * l3c * m3 * td1 ** 2 * sin(2 * t2 + 2 * t3)
          + (3 * l2 * l3c * m3 * td1 ** 2 * sin(2 * t2 + 3 * t3)) / 2)
    return C2, C3


@pytest.mark.parametrize("alpha1", [-math.pi / 2, math.pi / 2])
def test_appendix_f_mass_term_and_appendix_b_centrifugal_terms(alpha1):
    ch = thesis_chain(alpha1)
    rng = np.random.default_rng(0)
    for t1, t2, t3 in rng.uniform(-2, 2, size=(25, 3)):
        td = rng.normal(size=3)
        M = ch.mass_matrix([t1, t2, t3])
        assert M[0, 0] == pytest.approx(appendix_f_M1(t2, t3), rel=1e-12)
        C = ch.coriolis([t1, t2, t3], td)
        C2, C3 = appendix_b_C(t2, t3, *td)
        assert C[1] == pytest.approx(C2, rel=1e-9, abs=1e-16)
        assert C[2] == pytest.approx(C3, rel=1e-9, abs=1e-16)


def test_zoo_inertia_is_the_thesis_rod_with_printed_com_vectors():
    """gripkit's default finger uses I_C = diag(0, m|pc|², m|pc|²) and the printed pc vectors; its
    abduction mass term differs from the printed M1 (com on the axis) by < 0.01 % at θ = 0."""
    f = finger(check=False)
    v = f.parameters.value
    for k, (m, lc) in enumerate(zip((M1_, M2_, M3_), LC), start=1):
        assert v(f"I{k}_xx") == 0.0
        assert v(f"I{k}_yy") == v(f"I{k}_zz") == pytest.approx(m * lc * lc, rel=1e-12)
    finding = [x for x in f.consistency_checks() if x.check == "appendix-F-M1"][0]
    assert finding.consistent and finding.rel_error < 1e-3


def test_rotor_inertia_dominates_the_mass_matrix():
    """Appendix A: Im·N² = 5.1e-7 × 208.3² = 0.0221 kg·m² at the distal drive, ~100× the links."""
    ch = finger(check=False).chain()
    M = ch.mass_matrix(np.zeros(3))
    assert M[2, 2] == pytest.approx(5.1e-7 * 208.3 ** 2, rel=0.01)
    assert M[2, 2] - 5.1e-7 * 208.3 ** 2 < 0.01 * M[2, 2]
