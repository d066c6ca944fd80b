"""Sensor presets: the chirp, frame, antenna and detection settings of single-chip sensors in
their vendors' demo configurations. ``docs/fmcw.md`` traces every value to its source.

Units are the config's (SI; antenna positions in half wavelengths). TX numbers are 1-based as in
the vendor's documents (TX1, TX2, TX3).
"""

from __future__ import annotations

from typing import Any


def dbm_to_watts(dbm: float) -> float:
    """Power in dBm -> watts."""
    return float(10.0 ** ((dbm - 30.0) / 10.0))


#: TX1 at the origin, TX2 one wavelength across and half a wavelength up, TX3 two wavelengths
#: across; four RX half a wavelength apart (x, z in half wavelengths). The 12 virtual antennas:
#: 8 in an azimuth row (TX1, TX3) and 4 half a wavelength above (TX2).
_THREE_TX_ELEVATION = {
    "tx_positions": [(0.0, 0.0), (2.0, 1.0), (4.0, 0.0)],
    "rx_positions": [(0.0, 0.0), (1.0, 0.0), (2.0, 0.0), (3.0, 0.0)],
}

PRESETS: dict[str, dict[str, Any]] = {
    # TI IWR1443BOOST with `1443es1_short_range_3d.cfg` of the ti_mmwave_rospkg ROS driver:
    # profileCfg 0 77 7 7 57.14 0 0 70 1 240 4884 0 0 30; chirpCfg TX masks 1, 4, 2;
    # frameCfg 0 2 16 0 33.333 1 0; cfarCfg (range, CASO, window 8, guard 4); peakGrouping
    # along Doppler; multiObjBeamForming 1 0.5; clutterRemoval 0. The RadHAR recordings.
    # TI's IWR1443 data sheet (SWRS211): TX power 12 dBm, RX noise figure 16 dB from 77 to
    # 81 GHz (where this chirp sweeps). The antenna gain is the board's, not in the data sheet.
    "iwr1443_short_range_3d": {
        "start_frequency": 77e9,
        "slope": 70e12,
        "idle_time": 7e-6,
        "adc_start_time": 7e-6,
        "ramp_end_time": 57.14e-6,
        "sample_rate": 4.884e6,
        "n_samples": 240,
        "n_loops": 16,
        "tdm_order": [1, 3, 2],
        "frame_period": 33.333e-3,
        "max_bandwidth": 4e9,
        "transmit_power": dbm_to_watts(12.0),
        "noise_figure_db": 16.0,
        **_THREE_TX_ELEVATION,
        "cfar_range": {"mode": "so", "train": 8, "guard": 4, "threshold_db": 15.0},
        "cfar_doppler": None,
        "peak_grouping": ["doppler"],
        "multi_object_threshold": 0.5,
        "clutter_removal": False,
        "receiver_noise": True,
    },
    # TI IWR6843ISK with `ISK_6m_default.cfg` of TI's 3D people counting lab (mmWave Industrial
    # Toolbox): profileCfg 0 60.75 30.00 25.00 59.10 ... 54.71 1 96 2950.00; chirpCfg TX masks
    # 1, 2, 4; frameCfg 0 2 96 0 55.00 1 0; antGeometry0/1 give the virtual array (the same
    # three-TX layout as above). That lab detects in range-angle; the detection settings here
    # are this simulator's range-Doppler CFAR. TI's IWR6843 data sheet (SWRS219): TX power
    # 12 dBm, RX noise figure 12 dB (60 to 64 GHz).
    "iwr6843isk_people_counting_6m": {
        "start_frequency": 60.75e9,
        "slope": 54.71e12,
        "idle_time": 30e-6,
        "adc_start_time": 25e-6,
        "ramp_end_time": 59.10e-6,
        "sample_rate": 2.95e6,
        "n_samples": 96,
        "n_loops": 96,
        "tdm_order": [1, 2, 3],
        "frame_period": 55e-3,
        "max_bandwidth": 4e9,
        "transmit_power": dbm_to_watts(12.0),
        "noise_figure_db": 12.0,
        **_THREE_TX_ELEVATION,
        "cfar_range": {"mode": "ca", "train": 8, "guard": 2, "threshold_db": 15.0},
        "cfar_doppler": {"mode": "ca", "train": 4, "guard": 2, "threshold_db": 10.0},
        "peak_grouping": ["doppler", "range"],
        "multi_object_threshold": 0.5,
        "clutter_removal": True,
        "receiver_noise": True,
    },
}
