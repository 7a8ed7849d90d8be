#!/usr/bin/env python3
"""Fits the rational function the area-light shaders use for an LTC edge's
theta / sin(theta) / (2 pi) (shaders/include/ltc.glsl `ltc_edge`,
engine/ltc/src/polygon.rs `edge_factor`): for y = cos(theta) in [0, 1],
(p0 + p1 y + p2 y^2) / (q0 + q1 y + y^2), by iteratively reweighted linear
least squares on relative error; negative cosines use
theta / sin(theta) = pi / sin(theta) - theta' / sin(theta') with theta' = pi - theta.

    python3 tools/fit_ltc_edge.py
"""
import numpy as np

y = np.linspace(0.0, 1.0, 20001)
theta = np.arccos(y)
s = np.sin(theta)
f = np.where(s > 1e-9, theta / np.where(s > 1e-9, s, 1.0), 1.0) / (2.0 * np.pi)
A = np.stack([np.ones_like(y), y, y * y, -f, -f * y], 1)
b = f * y * y
solution, *_ = np.linalg.lstsq(A, b, rcond=None)
for _ in range(8):
    p0, p1, p2, q0, q1 = solution
    weight = 1.0 / ((q0 + q1 * y + y * y) * f)
    solution, *_ = np.linalg.lstsq(A * weight[:, None], b * weight, rcond=None)
p0, p1, p2, q0, q1 = solution
fit = (p0 + p1 * y + p2 * y * y) / (q0 + q1 * y + y * y)
print("p0 p1 p2 q0 q1 =", " ".join(f"{c:.8f}" for c in solution))
print(f"largest relative error on [0, 1]: {np.max(np.abs(fit - f) / f):.2e}")
