# SPDX-License-Identifier: GPL-2.0-or-later
"""Error measures between AO images and the Pareto front of (time, error) points."""
import math

import numpy as np

from config import SKY_DEPTH


def foreground(depth):
    """The pixels whose error counts: geometry, not the sky (SKY_DEPTH)."""
    return np.isfinite(depth) & (depth > 0) & (depth < SKY_DEPTH)


def error_stats(ao, reference, mask):
    """RMSE, mean absolute error, mean signed bias (ao - reference) and PSNR
    (peak 1) over the pixels where mask is true."""
    difference = (np.asarray(ao, np.float64) - np.asarray(reference, np.float64))[mask]
    if difference.size == 0:
        raise ValueError("no foreground pixels to compare")
    mse = float(np.mean(difference * difference))
    return {
        "rmse": math.sqrt(mse),
        "mae": float(np.mean(np.abs(difference))),
        "bias": float(np.mean(difference)),
        "psnr": 10.0 * math.log10(1.0 / mse) if mse > 0 else math.inf,
    }


def pareto_front(points):
    """Indices of the points (time, error) that no other point beats on both:
    sorted by time, each one has a lower error than every faster one."""
    order = sorted(range(len(points)), key=lambda k: (points[k][0], points[k][1]))
    front, best_error = [], math.inf
    for k in order:
        if points[k][1] < best_error:
            front.append(k)
            best_error = points[k][1]
    return front


def monte_carlo_scale(series):
    """a in rmse = a / sqrt(samples), fitted in log space to the Cycles series
    [(samples, seconds, rmse), ...] (every point weighs the same)."""
    samples = np.array([s for s, _, _ in series], np.float64)
    rmse = np.array([e for _, _, e in series], np.float64)
    return math.exp(float(np.mean(np.log(rmse) + 0.5 * np.log(samples))))


def cycles_time_for_rmse(series, target_rmse):
    """Seconds Cycles needs to reach target_rmse, from its measured series
    [(samples, seconds, rmse), ...]: Monte Carlo error falls as a / sqrt(N) and
    the time grows as t0 + c N, both fitted by least squares. Returns
    (samples, seconds); samples below 1 are clamped to 1 (one sample is the
    least a render takes)."""
    samples = np.array([s for s, _, _ in series], np.float64)
    seconds = np.array([t for _, t, _ in series], np.float64)
    needed = max(1.0, (monte_carlo_scale(series) / target_rmse) ** 2)
    slope, intercept = np.polyfit(samples, seconds, 1)
    return needed, float(max(intercept + slope * needed, seconds.min()))
