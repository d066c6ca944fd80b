"""Physical constants and fixed conventions (SI units throughout).

Every module that needs the speed of light imports it from here, so code and tests agree on the
exact value (using 3e8 would move Doppler values by 0.07 %).
"""

from __future__ import annotations

import scipy.constants

#: Speed of light in vacuum [m/s], exact.
SPEED_OF_LIGHT: float = float(scipy.constants.speed_of_light)

#: Boltzmann constant [J/K].
BOLTZMANN: float = float(scipy.constants.Boltzmann)
