"""Physical constants and fixed conventions (SI units throughout).

Every module that needs the speed of light imports it from here, so code and tests agree on the
exact value (using 3e8 moves Doppler values by 0.07 %).
"""

from __future__ import annotations

#: Speed of light in vacuum [m/s], exact by the definition of the metre (SI 2019).
SPEED_OF_LIGHT: float = 299_792_458.0

#: Boltzmann constant [J/K], exact by the definition of the kelvin (SI 2019).
BOLTZMANN: float = 1.380649e-23

# Written out rather than taken from scipy.constants so that importing the core does not import
# scipy (start-up time); tests/test_radar_physics.py checks both against scipy.constants.
