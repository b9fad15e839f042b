"""Prints the golden values of tests/shape/shape_test.cpp's scikit-learn comparison.

The points, values and noise are chosen here; scikit-learn's GaussianProcessRegressor (no
hyper-parameter fitting, no normalisation) predicts the mean and the latent standard deviation
with ConstantKernel(s^2) * Matern(l, nu) and alpha = the per-point noise variances.
Run: python3 tests/shape/gp_golden.py
"""
import numpy as np
from sklearn.gaussian_process import GaussianProcessRegressor
from sklearn.gaussian_process.kernels import ConstantKernel, Matern

rng = np.random.default_rng(7)
x = rng.uniform(-0.02, 0.02, size=(9, 3))
y = rng.normal(0.0, 0.004, size=9)
noise = rng.uniform(1e-8, 4e-7, size=9)
q = rng.uniform(-0.025, 0.025, size=(5, 3))
np.set_printoptions(precision=17)


def arr(name, a):
    flat = ", ".join(repr(float(v)) for v in np.ravel(a))
    print(f"const std::vector<double> {name}{{{flat}}};")


arr("kX", x)
arr("kY", y)
arr("kNoise", noise)
arr("kQ", q)
for nu, tag in ((1.5, "32"), (2.5, "52")):
    kernel = ConstantKernel(1e-4, "fixed") * Matern(0.01, "fixed", nu=nu)
    gp = GaussianProcessRegressor(kernel, alpha=noise, optimizer=None, normalize_y=False)
    gp.fit(x, y)
    mean, std = gp.predict(q, return_std=True)
    arr(f"kMean{tag}", mean)
    arr(f"kStd{tag}", std)
