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


def samples_for_rmse(points, target_rmse):
    """The sample count at which Cycles reaches target_rmse, from its measured
    [(samples, rmse), ...]: on the straight line in log RMSE against log
    samples through the two counts that bracket it (the last two where none
    reaches it; 1 where one sample does). At a few samples Cycles' error falls
    faster than a / sqrt(N) (its sampling is stratified: RMSE x sqrt(N) falls
    by about two fifths from 1 to 8 samples in the quick benchmark's scenes), so one a
    fitted to the whole series would put the count too low or too high."""
    points = sorted(points)
    if target_rmse >= points[0][1]:
        return 1.0
    more = next((k for k, (_, rmse) in enumerate(points) if rmse <= target_rmse),
                len(points) - 1)
    (fewer_samples, high), (more_samples, low) = points[more - 1], points[more]
    slope = math.log(high / low) / math.log(more_samples / fewer_samples)
    return max(1.0, fewer_samples * math.exp(math.log(high / target_rmse) / slope))


def cycles_time_for_rmse(series, target_rmse):
    """Seconds Cycles needs to reach target_rmse, from its measured series
    [(samples, seconds, rmse), ...]: the sample count by samples_for_rmse, the
    time at it on t0 + c N fitted by least squares. Returns (samples,
    seconds)."""
    samples = np.array([s for s, _, _ in series], np.float64)
    seconds = np.array([t for _, t, _ in series], np.float64)
    needed = samples_for_rmse([(s, e) for s, _, e in series], target_rmse)
    slope, intercept = np.polyfit(samples, seconds, 1)
    return needed, float(max(intercept + slope * needed, seconds.min()))
