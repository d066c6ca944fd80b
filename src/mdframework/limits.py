"""Documented limits of every input, and the checks that readers run before they allocate.

Every number a user can give (config fields, values in motion files) is finite and lies within a
physical range; the ranges are listed in ``docs/input-rules.md``. Config models take their bounds
from the constants here (through the annotated types of :mod:`mdframework.settings`); file readers
call :func:`check_declared_count`, :func:`check_values` and :func:`check_time_stamps`, which raise
:class:`~mdframework.errors.DataFileError` naming the file, the line and the problem.

The limits are generous for human motion and radar (a scene of 10 km, recordings of a day) and
exist so that absurd values (``1e308``, ``inf``, a declared count of ``10**12``) stop with a clear
message before they overflow or exhaust memory.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .errors import DataFileError, SceneError

#: Largest |x|, |y|, |z| of any position (config or motion data) [m].
MAX_COORDINATE_M = 10_000.0
#: Largest |coordinate| of a depth-camera (Kinect) joint [m]: the sensors see up to ~8 m.
MAX_SENSOR_COORDINATE_M = 100.0
#: Largest |coordinate| in the file units of a motion-capture file (BVH, ASF/AMC): the scene
#: limit in millimetres, the smallest unit such files use.
MAX_FILE_COORDINATE = MAX_COORDINATE_M * 1000.0
#: Largest |angle| of a rotation channel in a motion-capture file [deg] (unwrapped angles of a
#: subject turning many times are allowed).
MAX_ANGLE_DEG = 100_000.0
#: Longest recording, window or time stamp [s] (one day).
MAX_DURATION_S = 86_400.0
#: Largest |time stamp| [s] of a file whose times count from its first frame (joint tables):
#: clock times such as Unix epoch seconds are accepted up to the year 2286.
MAX_CLOCK_TIME_S = 1e10
#: Frame rates of recordings and generated tracks [Hz].
MIN_FRAME_RATE_HZ = 1.0
MAX_FRAME_RATE_HZ = 10_000.0
#: Most frames a motion file may declare or hold, and the largest frame number in one.
MAX_FRAMES = 10_000_000
MAX_FRAME_NUMBER = 1_000_000_000
#: Carrier frequency range [Hz] (1 MHz .. 1 THz).
MIN_CARRIER_HZ = 1e6
MAX_CARRIER_HZ = 1e12
#: Largest chirp, noise or sampling bandwidth [Hz].
MAX_BANDWIDTH_HZ = 1e12
#: Pulse repetition frequency range [Hz].
MIN_PRF_HZ = 1.0
MAX_PRF_HZ = 1e7
#: Most pulses in one run (record length x PRF).
MAX_PULSES = 5_000_000
#: Largest radar cross section of a point [m^2].
MAX_RCS_M2 = 1e6
#: Largest echo power [W] of a 1 m^2 scatterer 1 m from the radar, the range equation's
#: P G^2 lambda^2 / ((4 pi)^3 L) (a 1 MW planetary radar with a 73 dBi dish at 2.38 GHz,
#: Arecibo's: 3.2e15 W; a 1 MW radar with a 60 dBi antenna at 10 GHz: 4.5e11 W); far stronger
#: (1e20 W still runs with a 1e6 m^2 point at 0.5 m in a 65536-point STFT), the echoes of near,
#: large scatterers overflow the float32 arithmetic of the radars and of the spectrogram.
MAX_ECHO_POWER_W = 1e16
#: Smallest such echo power [W] (-270 dBm; a 1 mW radar at 60 GHz with 0 dBi and 100 dB of
#: losses gives 1.3e-21 W): far weaker (about 1e-44 W for a walk 6 m away; a walk 10 km away
#: still runs at 2e-31 W), every echo vanishes below float32's smallest numbers and the
#: spectrogram is silent (which stops a dataset build).
MIN_ECHO_POWER_W = 1e-30
#: Largest speed of a generated target or walker [m/s].
MAX_TARGET_SPEED_MPS = 1_000.0
MAX_PERSON_SPEED_MPS = 15.0
#: Largest magnitude of a decibel value (gains, losses, ratios) [dB].
MAX_DB = 400.0
#: Largest config file [bytes] and deepest nesting of tables and lists in it.
MAX_CONFIG_BYTES = 4 * 1024 * 1024
MAX_CONFIG_DEPTH = 32
#: Largest motion-capture text file (BVH, ASF, AMC, TRC, Kinect text, text table) [bytes]:
#: 256 MiB, about 45 minutes of a CMU AMC at 120 Hz (reading an AMC takes about 13 times its
#: size in memory at its peak).
MAX_MOTION_TEXT_BYTES = 256 * 1024 * 1024
#: Largest array of a binary motion file (a table's NPZ member), uncompressed [bytes]: 512 MiB,
#: 6.7e7 float64 values (about 2 hours of 25 joints at 120 Hz); checked from the sizes the file
#: declares, before anything is decompressed (a small compressed file can expand to gigabytes).
MAX_MOTION_ARRAY_BYTES = 512 * 1024 * 1024
#: Most records one dataset config may plan.
MAX_RECORDS = 1_000_000
#: Largest |value| of a random distribution's parameters in a dataset config (what is drawn
#: must then lie in the range of the field it is drawn into).
MAX_DRAWN_NUMBER = 1e12
#: Most frames per second of ``mdf show``'s animation (a GIF's frame delays are whole hundredths
#: of a second; one frame a millisecond of a long record would render for hours).
MAX_ANIMATION_FPS = 100

#: Most complex values in one radar frame's largest array (an FMCW radar's IF samples or
#: range profiles of every chirp and receive antenna, or its range-Doppler cube): 2**24, that is
#: 256 MiB at complex128 (a TI sensor's largest frame, 255 loops x 12 virtual antennas x 1024
#: range bins, is 3.1e6).
MAX_FRAME_CELLS = 2**24
#: Most bytes of the arrays a radar keeps for a whole record besides the slow-time signal (an
#: FMCW radar's range-Doppler map of every frame).
MAX_PRODUCT_BYTES = 2**30

#: Most values (Doppler bins x frames) in one record's spectrogram: 2**30, 4 GiB of float32
#: power (a record of MAX_PULSES pulses with a hop of 8 and 1024 Doppler bins holds 6.4e8).
MAX_SPECTROGRAM_CELLS = 2**30

#: Bytes the streaming pipeline holds per pulse of a record (time, gate range, the complex
#: slow-time signal and its float32 STFT input): with :data:`SCATTERER_PULSE_BYTES` per
#: scatterer when the result keeps every scatterer (``processing.keep_scatterers``), the basis
#: of the memory estimate in :func:`check_pulses`.
_BYTES_PER_PULSE = 8 + 8 + 16 + 8
#: Bytes a block of the streaming pipeline holds per scatterer and pulse at its peak: the
#: positions, ranges and RCS and the model's, the effects' and the radar's temporaries (traced
#: peaks of 100 bytes for ellipsoids and 150 with multipath's bounced paths, analytic path).
SCATTERER_PULSE_BYTES = 160


def memory_estimate_bytes(
    n_pulses: float, n_scatterers: int, keep_scatterers: bool = False
) -> float:
    """Approximate bytes a run of ``n_pulses`` holds for the whole record (the per-block
    arrays of the streaming pipeline do not grow with it, unless every scatterer is kept)."""
    per_pulse = _BYTES_PER_PULSE
    if keep_scatterers:
        per_pulse += SCATTERER_PULSE_BYTES * max(n_scatterers, 1)
    return n_pulses * per_pulse


def _size(n_bytes: float) -> str:
    for unit in ("B", "KiB", "MiB", "GiB", "TiB", "PiB"):
        if n_bytes < 1024 or unit == "PiB":
            return f"{n_bytes:.3g} {unit}"
        n_bytes /= 1024
    raise AssertionError("unreachable")  # pragma: no cover


def pulse_count(duration_s: float, prf_hz: float) -> float:
    """Pulses in a record of ``duration_s`` at ``prf_hz`` (a float: it may be absurdly large)."""
    return float(np.floor(duration_s * prf_hz)) + 1.0


def check_pulses(
    duration_s: float,
    prf_hz: float,
    n_scatterers: int,
    where: str,
    keep_scatterers: bool = False,
) -> None:
    """Refuse a run of more than :data:`MAX_PULSES` pulses, saying how much memory it would take.

    ``where`` names what to change (e.g. ``"motion.duration"``). Raises :class:`SceneError`.
    """
    n = pulse_count(duration_s, prf_hz)
    if n > MAX_PULSES:
        need = _size(memory_estimate_bytes(n, n_scatterers, keep_scatterers))
        kept = f", keeping {n_scatterers} scatterer(s) per pulse" if keep_scatterers else ""
        raise SceneError(
            f"{where}: a record of {duration_s:g} s at {prf_hz:g} pulses/s is {n:.4g} pulses "
            f"(about {need} of memory{kept}); the limit is {MAX_PULSES:,} pulses: shorten the "
            "record or lower the pulse rate (the PRF; FMCW: the chirps per second)"
        )


def check_echo_power(power_w: float, field: str = "radar.gain_dbi") -> None:
    """Refuse a radar whose range equation gives a 1 m^2 scatterer at 1 m an echo of
    ``power_w`` [W] above :data:`MAX_ECHO_POWER_W` or below :data:`MIN_ECHO_POWER_W`, naming
    ``field`` (the setting most to blame)."""
    what = (
        f"the echo of 1 m^2 at 1 m would carry {power_w:.3g} W (transmit_power x gain^2 x "
        "wavelength^2 / ((4 pi)^3 x losses))"
    )
    if not power_w <= MAX_ECHO_POWER_W:
        raise SceneError(
            f"{field}: {what}, more than {MAX_ECHO_POWER_W:g} W: lower gain_dbi or transmit_power"
        )
    if not power_w >= MIN_ECHO_POWER_W:
        raise SceneError(
            f"{field}: {what}, less than {MIN_ECHO_POWER_W:g} W, too weak for the "
            "arithmetic: raise gain_dbi or transmit_power, or lower the losses"
        )


def check_frame_cells(shape: tuple[int, ...], what: str, field: str) -> None:
    """Refuse a radar setting whose frame needs an array (``what``, of axes' lengths ``shape``)
    of more than :data:`MAX_FRAME_CELLS` complex values; ``field``: the field the message names.
    Raises ``ValueError`` (for config validators)."""
    n = math.prod(shape)
    if n > MAX_FRAME_CELLS:
        raise ValueError(
            f"{field}: one frame's {what} ({' x '.join(map(str, shape))}) is {n:,} complex "
            f"values (about {_size(16.0 * n)}); the limit is {MAX_FRAME_CELLS:,}: use fewer "
            "loops, samples or antennas, or smaller FFT sizes"
        )


def check_spectrogram_cells(
    nfft: int, n_frames: int, item_bytes: int, fields: tuple[str, str]
) -> None:
    """Refuse a spectrogram of ``nfft`` Doppler bins x ``n_frames`` frames of more than
    :data:`MAX_SPECTROGRAM_CELLS` values (``item_bytes`` per value, for the memory it would
    take), before any pulse is computed. ``fields``: the config field the message names and a
    clause saying what to change (the radar's
    :meth:`~mdframework.RadarWaveform.smaller_spectrogram`). Raises :class:`SceneError`."""
    n = float(nfft) * float(n_frames)
    if n > MAX_SPECTROGRAM_CELLS:
        field, advice = fields
        raise SceneError(
            f"{field}: the spectrogram of {nfft} Doppler bins x {n_frames} frames is "
            f"{n:.4g} values (about {_size(item_bytes * n)} of memory); the limit is "
            f"{MAX_SPECTROGRAM_CELLS:,}: {advice}"
        )


def check_product_bytes(n_bytes: float, what: str, field: str) -> None:
    """Refuse a record whose kept radar products (``what``) would take more than
    :data:`MAX_PRODUCT_BYTES`; ``field`` is what to change. Raises :class:`SceneError`."""
    if n_bytes > MAX_PRODUCT_BYTES:
        raise SceneError(
            f"{field}: {what} would take about {_size(n_bytes)} of memory; the limit is "
            f"{_size(MAX_PRODUCT_BYTES)}: shorten the record or set {field} = false"
        )


def check_regular_file(path: str | Path) -> None:
    """Refuse a file that is not a regular file (or a link to one) before it is opened: a
    received folder's motion file may be a named pipe, or a link to ``/dev/zero``, and
    reading it would never end, or fill the memory. Raises
    :class:`~mdframework.errors.DataFileError` naming the file (also when it cannot be
    examined)."""
    import stat

    p = Path(path)
    try:
        mode = p.stat().st_mode
    except OSError as exc:
        raise DataFileError(p, f"cannot read: {exc.strerror or exc}") from None
    if not stat.S_ISREG(mode):
        what = "a folder" if stat.S_ISDIR(mode) else "not a regular file (a pipe or a device?)"
        raise DataFileError(p, f"cannot read: {what}")


def read_file_bytes(path: str | Path) -> bytes:
    """The bytes of a regular file (or a link to one), checked by :func:`check_regular_file`
    before it is opened. Raises :class:`~mdframework.errors.DataFileError` naming the file."""
    check_regular_file(path)
    try:
        return Path(path).read_bytes()
    except OSError as exc:
        raise DataFileError(Path(path), f"cannot read: {exc.strerror or exc}") from None


def check_file_size(path: str | Path, what: str, max_bytes: int) -> None:
    """Refuse a file of more than ``max_bytes`` before it is read; ``what`` names what it
    should be (``"a BVH file"``). Raises :class:`~mdframework.errors.DataFileError` naming the
    file, its size and the limit (also when it cannot be examined)."""
    p = Path(path)
    try:
        size = p.stat().st_size
    except OSError as exc:
        raise DataFileError(p, f"cannot read: {exc.strerror or exc}") from None
    if size > max_bytes:
        raise DataFileError(
            p, f"{size:,} bytes is beyond the limit of {max_bytes:,} bytes for {what}"
        )


def read_text_file(
    path: str | Path, what: str, max_bytes: int | None = None, latin1: bool = False
) -> str:
    """The text of a file that must be UTF-8 (a byte-order mark is dropped), checked before it
    is decoded: at most ``max_bytes`` long (when given), no NUL byte (binary data, or UTF-16).
    ``latin1``: text that is not UTF-8 is read as Latin-1 instead of refused (formats whose old
    writers put Windows paths in a header line).

    ``what`` names what the file should be (``"a text table"``). Raises
    :class:`~mdframework.errors.DataFileError` naming the file and the line of the first bad
    byte.
    """
    p = Path(path)
    if max_bytes is not None:
        check_file_size(p, what, max_bytes)
    raw = read_file_bytes(p)
    if b"\0" in raw:
        line = raw[: raw.index(b"\0")].count(b"\n") + 1
        raise DataFileError(p, f"binary data (a NUL byte): not {what}", line)
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        if latin1:
            return raw.decode("latin-1")
        line = raw[: exc.start].count(b"\n") + 1
        raise DataFileError(p, "not UTF-8 text: re-save the file as UTF-8", line) from None


def check_declared_count(
    path: str | Path,
    line: int,
    what: str,
    declared: int,
    available: int | None = None,
    per_item: int = 1,
) -> None:
    """A count declared in a file must fit the data present before anything is allocated for
    it: at most :data:`MAX_FRAMES`, and (when ``available`` is given) ``declared * per_item`` at
    most the ``available`` lines that follow."""
    if declared > MAX_FRAMES:
        raise DataFileError(path, f"{what} {declared} exceeds the limit of {MAX_FRAMES:,}", line)
    if available is not None and declared * per_item > available:
        raise DataFileError(
            path,
            f"{what} {declared} needs at least {declared * per_item} more line(s), but the file "
            f"holds {available}: the file is truncated or the count is wrong",
            line,
        )


def check_values(
    path: str | Path,
    values: ArrayLike,
    limit: float,
    what: str,
    line_of: Callable[[int], int] | Sequence[int] | None = None,
    unit: str = "",
    allow_nan: bool = False,
) -> None:
    """Every value finite and ``|value| <= limit`` (``allow_nan``: NaN marks a missing value
    and passes; infinities never do).

    ``values`` has its records along axis 0 (frames or lines); ``line_of`` maps a record index to
    its 1-based line in the file (a function or a sequence). The error names the first bad record.
    """
    a = np.asarray(values, dtype=np.float64)
    if a.size == 0:
        return
    rows = a.reshape(a.shape[0] if a.ndim else 1, -1)
    with np.errstate(invalid="ignore"):
        bad = ~(np.abs(rows) <= limit)  # NaN compares False: caught here too
    if allow_nan:
        bad &= ~np.isnan(rows)
    if not bad.any():
        return
    record = int(np.argmax(bad.any(axis=1)))
    value = float(rows[record][bad[record]][0])
    line = None
    if line_of is not None:
        line = line_of(record) if callable(line_of) else int(line_of[record])
    problem = "is not finite" if not np.isfinite(value) else f"is beyond +-{limit:g}{unit}"
    raise DataFileError(path, f"{what} {value!r} {problem}", line)


def check_time_stamps(path: str | Path, time: NDArray[np.float64], line: int | None = None) -> None:
    """Time stamps [s] finite, within +-:data:`MAX_DURATION_S`, spanning at least two distinct
    instants (a motion needs two)."""
    t = np.asarray(time, dtype=np.float64)
    check_values(path, t, MAX_DURATION_S, "time stamp", None, " s")
    if t.size < 2:
        raise DataFileError(
            path, f"only {t.size} frame(s): a motion needs at least two time stamps", line
        )
    if not np.any(t != t[0]):
        raise DataFileError(
            path,
            f"all {t.size} frames have the same time stamp ({t[0]:g} s): a motion needs at "
            "least two distinct time stamps",
            line,
        )
