import numpy as np, warnings
from gripkit import sysid
warnings.simplefilter("always")
rng = np.random.default_rng(0); N=600
u = np.ones(N); y = rng.standard_normal(N)
with warnings.catch_warnings(record=True) as w:
    m = sysid.narx(u, y, degree=2, lags=2)
print(m.fit_percent, [str(x.message)[:200] for x in w])
print(m)
