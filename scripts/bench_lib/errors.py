"""Errors against the Cycles reference with the reference's own noise taken out.

The reference is the mean of two Cycles bakes a, b with different seeds. At each probe,
the variance of that mean is estimated by (a − b)²/4 (unbiased). For a method's values x:
    MSE = mean((x − ref)²) − mean((a − b)²/4)     (clamped at 0)
    relative RMS = sqrt(MSE) / mean(ref)
    max error    = max over probes of sqrt(max(mean_rgb (x − ref)² − mean_rgb (a − b)²/4, 0))
                   / mean(ref)
all channels together."""
from __future__ import annotations

import numpy as np


def reference(a: np.ndarray, b: np.ndarray):
    ref = 0.5 * (a + b)
    noise = (a - b) ** 2 / 4.0
    return ref, noise


def errors(x: np.ndarray, ref: np.ndarray, noise: np.ndarray):
    ok = np.all(np.isfinite(x), axis=1)
    d2 = (x[ok] - ref[ok]) ** 2
    n2 = noise[ok]
    mean = float(ref.mean())
    mse = max(float(d2.mean() - n2.mean()), 0.0)
    per = np.maximum(d2.mean(1) - n2.mean(1), 0.0)
    worst = int(np.nonzero(ok)[0][np.argmax(per)])
    return dict(rel_rms=np.sqrt(mse) / mean, rel_max=float(np.sqrt(per.max())) / mean,
                missing=int((~ok).sum()), worst=worst)


def noise_rel_rms(ref: np.ndarray, noise: np.ndarray) -> float:
    """Relative RMS noise of the reference itself."""
    return float(np.sqrt(noise.mean()) / ref.mean())


def cycles_time_at(err: float, curve: list[tuple[float, float]]):
    """Cycles' time for error `err`, from its (time, error) points, linear in log-log.
    Returns (seconds, how) with how 'interpolated' or 'extrapolated'."""
    pts = sorted((e, t) for t, e in curve if e > 0 and t > 0)
    if len(pts) < 2:
        return float("nan"), "n/a"
    le = np.log([p[0] for p in pts])
    lt = np.log([p[1] for p in pts])
    x = np.log(err)
    if le[0] <= x <= le[-1]:
        return float(np.exp(np.interp(x, le, lt))), "interpolated"
    i, j = (0, 1) if x < le[0] else (-2, -1)
    slope = (lt[j] - lt[i]) / (le[j] - le[i]) if le[j] != le[i] else 0.0
    return float(np.exp(lt[i] + slope * (x - le[i]))), "extrapolated"
