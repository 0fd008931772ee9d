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
    [(samples, rmse), ...] (at least two counts, every RMSE above 0): on the
    straight line in log RMSE against log samples through the two counts
    that bracket it (the first two, or the last two, where it lies outside
    them; at least 1). At a few samples Cycles' error falls faster than
    a / sqrt(N) (its sampling is stratified: RMSE x sqrt(N) falls by about two
    fifths from 1 to 8 samples in the quick benchmark's scenes), so one a
    fitted to the whole series would put the count too low or too high; and
    it falls unevenly, powers of 2 doing best (terrain at 1080p: RMSE x
    sqrt(N) 0.238 at 8 samples, 0.251 at 9), so a count read between powers
    of 2 is if anything too low. Raises ValueError where the points cannot
    give one."""
    points = sorted(points)
    if (len({samples for samples, _ in points}) != len(points) or len(points) < 2
            or not target_rmse > 0 or any(not rmse > 0 for _, rmse in points)):
        raise ValueError(f"no sample count for RMSE {target_rmse} from {points}")
    if target_rmse >= points[0][1] and points[0][0] == 1:
        return 1.0
    more = next((k for k, (_, rmse) in enumerate(points) if rmse <= target_rmse),
                len(points) - 1)
    (fewer_samples, high), (more_samples, low) = points[max(more, 1) - 1], points[max(more, 1)]
    if not high > low:
        raise ValueError(f"Cycles' RMSE does not fall from {fewer_samples} to {more_samples} "
                         f"samples: {points}")
    slope = math.log(high / low) / math.log(more_samples / fewer_samples)
    return max(1.0, fewer_samples * math.exp(math.log(high / target_rmse) / slope))


def equal_error_count(rmse_at, target_rmse, most):
    """(count, N): Cycles' sample count for target_rmse, with rmse_at(n) its
    measured RMSE at n samples (a render each). N is the least whole count
    that reaches it (RMSE at most target_rmse): the first power of 2 that
    does (1, 2, 4, ... up to `most`) bounds it, and the counts after the
    power of 2 before are tried in turn, as Cycles' error falls unevenly
    between them. count lies in N - 1 to N, read log-log linear
    (samples_for_rmse; 1 where one sample reaches it). Raises ValueError
    where `most` samples do not reach it."""
    fewer, more = None, 1
    while rmse_at(more) > target_rmse:
        if more >= most:
            raise ValueError(f"Cycles at {more} samples does not reach RMSE {target_rmse:.4f}")
        fewer, more = more, 2 * more
    if fewer is None:
        return 1.0, 1
    whole = fewer + 1
    while rmse_at(whole) > target_rmse:
        whole += 1
    count = samples_for_rmse([(n, rmse_at(n)) for n in (whole - 1, whole)], target_rmse)
    return count, whole


def cycles_seconds_at(series, samples):
    """Cycles' time at `samples` from its measured [(samples, seconds), ...]:
    t0 + c N fitted by least squares, at least its fastest render's."""
    counts = np.array([n for n, _ in series], np.float64)
    seconds = np.array([t for _, t in series], np.float64)
    slope, intercept = np.polyfit(counts, seconds, 1)
    return float(max(intercept + slope * samples, seconds.min()))
