"""Identify one joint's inertia and friction from a position/effort log by inverse-dynamics least
squares (IDIM-LS: zero-phase filter, differentiate, decimate, solve), as one would on the
DLR/HIT Hand II finger (002_ddea254371185ad3.txt, ch. 6). The log is simulated: a joint with
known inertia, viscous and Coulomb friction driven by a multisine torque, position quantised.
The σ gripkit reports (Newey-West, for the filtered residuals' autocorrelation) covers the noise;
the few-tenths-of-a-percent errors left are systematic (the simulated Coulomb term is a smoothed
sign, the filter has finite bandwidth), which no σ from the data can reveal."""

import numpy as np

from gripkit.sysid.rigid_body.friction import idim_ls

fs, T = 1000.0, 20.0
t = np.arange(int(T * fs)) / fs
J, b, fc = 2.0e-4, 1.5e-3, 0.02                      # kg·m², N·m·s/rad, N·m
tau = 0.05 * (np.sin(2 * np.pi * 0.7 * t) + 0.6 * np.sin(2 * np.pi * 2.3 * t + 1.0))
q = np.empty(t.size)
x, v, h = 0.0, 0.0, 1.0 / (10 * fs)                  # semi-implicit Euler at 10 kHz
for k in range(t.size):
    q[k] = x
    for _ in range(10):
        v += h * (tau[k] - b * v - fc * np.tanh(v / 1e-4)) / J
        x += h * v
q = np.round(q / 1e-4) * 1e-4                         # 0.1 mrad encoder
res = idim_ls(q, tau, dt=1 / fs)
# σ covers the noise, not the filter's bias
for name, true in (("inertia", J), ("viscous", b), ("coulomb", fc)):
    print(f"{name}: {res.params[name]:.4g} ± {res.std[name]:.2g} (true {true:.4g}, "
          f"{100 * (res.params[name] / true - 1):+.2f} %)")
print(f"relative error of the fitted effort: {res.relative_error_percent:.2f} %")
