"""Spectral analysis of a run (Section 6.8): periodogram PSD in dB/Hz, Savitzky-Golay
smoothing, the largest peaks and the modal frequencies nearest to them.

A run's steps are not uniform (the step control refines at impacts), so every
signal is first put on a uniform grid: values by linear interpolation, impact
counts by binning (a rate in impacts per second).  The PSD is one-sided, in
(unit)^2/Hz, and 10 log10 of it in dB/Hz with reference intensity 1, as in the paper.
"""

from __future__ import annotations

import numpy as np
from scipy import signal

#: Savitzky-Golay window as a fraction of the number of frequency bins, and its order.
SMOOTHING_FRACTION = 0.01
SMOOTHING_ORDER = 3


def uniform_grid(t: np.ndarray, step: float | None = None) -> np.ndarray:
    """Uniform instants over [t0, tf]; the step defaults to the median step of the run."""
    step = float(np.median(np.diff(t))) if step is None else step
    n = int(np.floor((t[-1] - t[0]) / step)) + 1
    return t[0] + step * np.arange(n)


def resample(t: np.ndarray, values: np.ndarray, grid: np.ndarray) -> np.ndarray:
    """A sampled signal on the uniform grid (linear interpolation)."""
    return np.interp(grid, t, values)


def event_rate(t: np.ndarray, counts: np.ndarray, grid: np.ndarray) -> np.ndarray:
    """Events per second on the grid: counts at instants t binned into the grid cells."""
    step = grid[1] - grid[0]
    edges = np.append(grid - 0.5 * step, grid[-1] + 0.5 * step)
    binned, _ = np.histogram(t, bins=edges, weights=counts)
    return binned / step


def power_spectral_density(values: np.ndarray, step: float) -> tuple[np.ndarray, np.ndarray]:
    """(frequencies [Hz], one-sided PSD [unit^2/Hz]) by the periodogram of the mean-removed signal."""
    return signal.periodogram(values, fs=1.0 / step, detrend="constant", scaling="density")


#: Zero-padding of :func:`dominant_period`'s transform: bins this many times finer than the record's own.
PADDING = 16


def dominant_period(t: np.ndarray, values: np.ndarray) -> float | None:
    """The period [s] of the largest peak of the Hann-windowed power spectrum of a signal sampled at ``t``, its
    transform zero-padded :data:`PADDING` times and the peak placed by a parabola through the log power of its
    three bins; peaks below 1.5 cycles over the record are not counted.  None for a record too short or flat."""
    if t.size < 8 or np.ptp(values) == 0.0:
        return None
    grid = uniform_grid(t)
    g = resample(t, values, grid)
    g = (g - g.mean()) * np.hanning(g.size)
    size = 1 << int(np.ceil(np.log2(PADDING * g.size)))
    power = np.abs(np.fft.rfft(g, size)) ** 2
    freq = np.fft.rfftfreq(size, grid[1] - grid[0])
    low = int(np.searchsorted(freq, 1.5 / (grid[-1] - grid[0])))
    if low >= power.size - 1:
        return None
    k = low + int(np.argmax(power[low:-1]))
    if k == 0 or power[k] <= 0.0:
        return None
    a, b, c = np.log(np.maximum(power[k - 1:k + 2], 1e-300))
    shift = 0.5 * (a - c) / (a - 2.0 * b + c) if a - 2.0 * b + c < 0.0 else 0.0
    return float(1.0 / (freq[k] + shift * (freq[1] - freq[0])))


def to_db(psd: np.ndarray) -> np.ndarray:
    """10 log10(PSD / 1) in dB/Hz (floored at 1e-30 to stay finite)."""
    return 10.0 * np.log10(np.maximum(psd, 1e-30))


def smooth(db: np.ndarray) -> np.ndarray:
    """Savitzky-Golay smoothing of a PSD in dB (the paper's blue curves)."""
    window = max(SMOOTHING_ORDER + 2, int(SMOOTHING_FRACTION * len(db)) | 1)
    if window >= len(db):
        return db.copy()
    return signal.savgol_filter(db, window, SMOOTHING_ORDER)


#: Local maxima closer than this are one peak (a smoothed PSD wobbles on top of a broad peak) [Hz].
PEAK_SEPARATION_HZ = 1.0


def spectral_peaks(freq: np.ndarray, db: np.ndarray, count: int = 3, min_frequency: float = 0.0) -> list[dict]:
    """The ``count`` highest local maxima of a PSD in dB above ``min_frequency``, highest first,
    at least PEAK_SEPARATION_HZ apart."""
    distance = max(1, int(round(PEAK_SEPARATION_HZ / (freq[1] - freq[0]))))
    index, _ = signal.find_peaks(db, distance=distance)
    index = index[freq[index] > min_frequency]
    best = index[np.argsort(db[index])[::-1][:count]]
    return [{"frequency_hz": float(freq[i]), "psd_db": float(db[i])} for i in best]


def nearest_mode(frequency: float, modal_frequencies: np.ndarray, kinds: list[str]) -> dict:
    """The modal frequency closest to ``frequency`` and its family."""
    k = int(np.argmin(np.abs(modal_frequencies - frequency)))
    return {"mode_frequency_hz": float(modal_frequencies[k]), "mode_kind": kinds[k],
            "relative_difference": float(abs(frequency - modal_frequencies[k]) / modal_frequencies[k])}


#: Signals of Section 6.8: time-series name -> (what it is, unit of the PSD, paper figure).
SIGNALS = {
    "bit_velocity": ("drill-bit velocity", "(m/s)^2/Hz", "21"),
    "bit_angular_velocity": ("drill-bit angular velocity", "(rad/s)^2/Hz", "21"),
    "section_w_velocity": ("transverse velocity in z at the section", "(m/s)^2/Hz", "22"),
    "section_theta_x_velocity": ("angular velocity about x at the section", "(rad/s)^2/Hz", "22"),
    "impacts": ("impacts per unit time", "(1/s)^2/Hz", "23"),
}


def run_spectra(series: dict, modal_frequencies: np.ndarray, modal_kinds: list[str], peaks: int = 2,
                min_frequency: float = 1.0, held_modes: tuple | None = None) -> dict:
    """PSD (raw and smoothed, dB/Hz) of every signal of SIGNALS, with its ``peaks`` highest peaks
    above ``min_frequency`` (on the smoothed curve) and the nearest natural frequencies: of the free
    string, and, given ``held_modes`` = (frequencies, kinds), of the string held by the drive at x = 0
    as it is during a run (``held_mode_*``)."""
    t = series["time"]
    grid = uniform_grid(t)
    step = grid[1] - grid[0]
    out = {}
    for name, (label, unit, figure) in SIGNALS.items():
        values = event_rate(t, series[name], grid) if name == "impacts" else resample(t, series[name], grid)
        freq, psd = power_spectral_density(values, step)
        raw = to_db(psd)
        smoothed = smooth(raw)
        found = spectral_peaks(freq, smoothed, peaks, min_frequency) if np.any(psd > 0) else []
        for peak in found:
            peak.update(nearest_mode(peak["frequency_hz"], modal_frequencies, modal_kinds))
            if held_modes is not None:
                held = nearest_mode(peak["frequency_hz"], *held_modes)
                peak.update({f"held_{key}": value for key, value in held.items()})
        out[name] = {"label": label, "psd_unit": unit, "figure": figure, "frequency_hz": freq,
                     "psd_db": raw, "smoothed_db": smoothed, "peaks": found}
    return out
