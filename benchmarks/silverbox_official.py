"""gripkit's models on the Silverbox benchmark's official test parts, scored as the published
results are: RMS of the simulation error in mV.

The benchmark's record ``SNLS80mV.csv`` (131 072 samples, 2.6 MB, columns ``V1`` input, ``V2``
output; SilverboxFiles.zip of https://www.nonlinearbenchmark.org/benchmarks/silverbox) is not
in the repository (tests/fixtures/silverbox holds two 8192-sample cuts of it); give its path:

    PYTHONPATH=src python benchmarks/silverbox_official.py PATH/SNLS80mV.csv [--train official]

The file is checked against the sha256 in tests/fixtures/silverbox/README.md. Splits as the
benchmark's official loader (``nonlinear_benchmarks.Silverbox``, M. Schoukens and G. Beintema;
0-based sample indices of the record):

* estimation: ``--train fixture`` (default) the fixture's cut, samples [40960, 49152) (it lies
  inside the official training part); ``--train official``: the whole official training part,
  the first 75 % of the multisines [40650, 127400), i.e. [40650, 105712);
* tests: ``multisine`` [105712, 127400), ``arrow full`` [100, 40575) (its last part extrapolates
  to amplitudes above any in the training data), ``arrow no extrapolation`` [100, 32100).

Every model is chosen without the test parts (NARX: BIC; Hammerstein–Wiener: its default
structure search on the estimation record). Each free run starts on the test part alone (NARX:
from its first 2 measured outputs; Hammerstein–Wiener: from the steady state at its first input
sample; nonlinear state space: from rest) and e_RMS = sqrt(mean((y - ŷ)²)) is taken after the
first 50 samples, the benchmark's state-initialisation window."""

import argparse
import hashlib
import sys
import time
import warnings
from pathlib import Path

import numpy as np

FIXTURES = Path(__file__).resolve().parents[1] / "tests" / "fixtures"
FIXTURE_README = FIXTURES / "silverbox" / "README.md"
SHA256 = "ae62d5a91230c10f76e6dd02c8a4fac3c9d4d8a95fbf50e87cb0c4885003e0f1"
TRAIN = {"fixture": (40960, 49152), "official": (40650, 105712)}
TESTS = (("multisine", 105712, 127400), ("arrow full", 100, 40575),
         ("arrow no extrapolation", 100, 32100))
INIT = 50  # the benchmark's state-initialisation window (samples not scored)


def load(path: Path) -> tuple[np.ndarray, np.ndarray]:
    data = path.read_bytes()
    digest = hashlib.sha256(data).hexdigest()
    if digest != SHA256:
        sys.exit(f"error: {path}: sha256 {digest}, expected {SHA256} (SNLS80mV.csv of "
                 "SilverboxFiles.zip, as named in tests/fixtures/silverbox/README.md)")
    assert SHA256 in FIXTURE_README.read_text()
    rec = np.genfromtxt(path, delimiter=",", skip_header=1, usecols=(0, 1))
    return rec[:, 0], rec[:, 1]


def rms_mv(y: np.ndarray, ys: np.ndarray) -> float | None:
    e = y[INIT:] - np.asarray(ys).ravel()[INIT:]
    return None if not np.all(np.isfinite(e)) else 1e3 * float(np.sqrt(np.mean(e ** 2)))


def main() -> None:
    from gripkit.sysid import hammerstein_wiener, narx, nlss

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("path", type=Path)
    ap.add_argument("--train", choices=tuple(TRAIN), default="fixture")
    ap.add_argument("--hw", action="store_true", help="also the Hammerstein-Wiener model")
    ap.add_argument("--nlss", action="store_true", help="also the nonlinear state-space model")
    args = ap.parse_args()
    u, y = load(args.path)
    a, b = TRAIN[args.train]
    ue, ye = u[a:b], y[a:b]
    models = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        t = time.perf_counter()
        models["linear (degree-1 NARX, lags 2, refined on the simulation error)"] = narx(
            ue, ye, degree=1, lags=2, refine="simulation")
        models["NARX (cubic, lags 2, BIC, refined on the simulation error)"] = narx(
            ue, ye, degree=3, lags=2, refine="simulation")
        if args.hw:
            models["Hammerstein-Wiener (default structure search)"] = hammerstein_wiener(
                ue, ye, dt=1.0)
        if args.nlss:
            models["nonlinear state space (default order, degree 3)"] = nlss(
                (ue, ye), degree=3, progress=False)
        fitted = time.perf_counter() - t
        print(f"estimation: samples [{a}, {b}) ({b - a}), models fitted in {fitted:.1f} s")
        print("| model | " + " | ".join(f"{n} [{s}, {e})" for n, s, e in TESTS) + " |")
        print("|---|" + "---|" * len(TESTS))
        for name, m in models.items():
            cells = []
            for _, s, e in TESTS:
                ut, yt = u[s:e], y[s:e]
                ys = m.simulate(ut, yt[:2]) if hasattr(m, "terms") else m.simulate(ut)
                r = rms_mv(yt, ys)
                cells.append("diverges" if r is None else f"{r:.3g} mV")
            print(f"| {name} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
