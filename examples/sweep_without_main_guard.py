"""A sweep on a local process pool, started at the top level of a script: gripkit's workers are
fresh subprocesses that never re-import this file, so no `if __name__ == "__main__"` is needed."""

from pathlib import Path

import numpy as np

from gripkit.batch import SweepSpec, sweep

spec = SweepSpec.from_toml(Path(__file__).with_name("sweep_mass_spring_damper.toml"))
result = sweep(spec, backend="process", workers=2, progress=False)
print(result.summary())
for k in (1.0, 4.0, 16.0):
    m = result["k"] == k
    print(f"k = {k:5.1f} N/m: overshoot "
          f"{np.mean(result['overshoot_percent'][m]):5.1f} % on average")
