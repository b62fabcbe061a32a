"""Measurements of rendered drill sound: what the tests, the browser check and the benchmark read from samples.

No speakers here: the sound is checked in its spectrum (peaks at k * rpm / 60),
its clicks (onsets counted) and its smoothness at a parameter change (how far
it jumps from the unchanged sound), all from a buffer of samples.
"""

from __future__ import annotations

import math

import numpy as np

from . import drillsound


def spectrum(samples: np.ndarray, sample_rate: int = drillsound.SAMPLE_RATE, padding: int = 4):
    """Frequencies (Hz) and magnitudes of a Hann-windowed, zero-padded FFT."""
    samples = np.asarray(samples, dtype=float)
    size = 1 << int(math.ceil(math.log2(len(samples) * padding)))
    magnitude = np.abs(np.fft.rfft(samples * np.hanning(len(samples)), size))
    return np.fft.rfftfreq(size, 1.0 / sample_rate), magnitude


def peak_near(frequencies, magnitude, near_hz: float, relative_window: float = 0.1):
    """The strongest peak within ``near_hz`` * (1 +- relative_window): its frequency, refined by a parabola
    through the log magnitudes of its bin and neighbours, and its prominence (peak over the window's median)."""
    window = np.nonzero((frequencies > near_hz * (1 - relative_window)) & (frequencies < near_hz * (1 + relative_window)))[0]
    if window.size < 3:
        raise ValueError(f"no spectrum around {near_hz:.1f} Hz")
    i = window[np.argmax(magnitude[window])]
    frequency = frequencies[i]
    if 0 < i < len(magnitude) - 1:
        a, b, c = np.log(magnitude[i - 1:i + 2] + 1e-30)
        denominator = a - 2 * b + c
        if denominator < 0:
            frequency += 0.5 * (a - c) / denominator * (frequencies[1] - frequencies[0])
    return float(frequency), float(magnitude[i] / (np.median(magnitude[window]) + 1e-30))


def harmonic_errors(samples, fundamental_hz: float, harmonics, sample_rate: int = drillsound.SAMPLE_RATE) -> dict:
    """Relative error of the peak found near each k * fundamental (k: (error, prominence)), for harmonics below 0.4 fs."""
    frequencies, magnitude = spectrum(samples, sample_rate)
    errors = {}
    for k in harmonics:
        target = k * fundamental_hz
        if target < 0.4 * sample_rate:
            found, prominence = peak_near(frequencies, magnitude, target)
            errors[k] = (found / target - 1.0, prominence)
    return errors


def strongest_frequency(samples, sample_rate: int = drillsound.SAMPLE_RATE, low_hz: float = 50.0) -> float:
    frequencies, magnitude = spectrum(samples, sample_rate)
    usable = frequencies > low_hz
    return float(frequencies[usable][np.argmax(magnitude[usable])])


def fundamental(samples, expected_hz: float, sample_rate: int = drillsound.SAMPLE_RATE, relative_window: float = 0.35) -> float:
    """The fundamental's frequency, searched within ``relative_window`` of a guess."""
    frequencies, magnitude = spectrum(samples, sample_rate, padding=8)
    return peak_near(frequencies, magnitude, expected_hz, relative_window)[0]


def click_onsets(samples, sample_rate: int = drillsound.SAMPLE_RATE, quiet_s: float = 0.0005, threshold: float = 0.01) -> np.ndarray:
    """Sample indices where a click starts: the level rises above ``threshold`` after ``quiet_s`` below it."""
    loud = np.abs(np.asarray(samples)) > threshold
    quiet = int(quiet_s * sample_rate)
    indices = np.nonzero(loud)[0]
    if indices.size == 0:
        return indices
    gaps = np.diff(indices)
    return np.concatenate(([indices[0]], indices[1:][gaps > quiet]))


def onset_jump(changed, reference, samples: int = 4) -> tuple[int | None, float]:
    """Where a changed sound first departs from the sound without the change, and by how much it moved
    within its first ``samples`` samples there (in full-scale units).

    The two renders are the same samples up to the change (the synthesis is
    deterministic), so a glide departs by a hair and a step by a jump.
    """
    difference = np.abs(np.asarray(changed, dtype=float) - np.asarray(reference, dtype=float))
    departed = np.nonzero(difference > 0.0)[0]
    if departed.size == 0:
        return None, 0.0
    first = int(departed[0])
    return first, float(difference[first:first + samples].max())


def changed_at(samples, reference, start: int, sample_rate: int = drillsound.SAMPLE_RATE, window_s: float = 0.001,
               relative: float = 0.1) -> int | None:
    """First sample at or after ``start`` where the difference from ``reference`` over a ``window_s`` window
    reaches ``relative`` (10 %: -20 dB) of the louder signal's level over that window; None if it never does."""
    window = max(1, int(window_s * sample_rate))
    difference = np.asarray(samples, dtype=float)[start:] - np.asarray(reference, dtype=float)[start:]
    if difference.size < window:
        return None
    kernel = np.ones(window) / window
    difference_rms = np.sqrt(np.convolve(difference ** 2, kernel, "valid"))
    level = np.sqrt(np.maximum(np.convolve(np.asarray(samples, dtype=float)[start:] ** 2, kernel, "valid"),
                               np.convolve(np.asarray(reference, dtype=float)[start:] ** 2, kernel, "valid")))
    hits = np.nonzero(difference_rms >= relative * np.maximum(level, 1e-6))[0]
    return None if hits.size == 0 else start + int(hits[0]) + window
