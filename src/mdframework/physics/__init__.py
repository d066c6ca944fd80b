"""The physics core: pure functions on numpy arrays. No I/O, no config, no plugins.

Modules: :mod:`.radar` (range equation, carrier phase, LFM pulse compression, Doppler bookkeeping),
:mod:`.rcs` (sphere and ellipsoid RCS), :mod:`.body` (segment table and scatterer placement),
:mod:`.interpolation` (resampling joint tracks to pulse times), :mod:`.scene` (placing a recording
in the scene), :mod:`.spectrogram` (two-sided STFT and dB conversion).
"""
