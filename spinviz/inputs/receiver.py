"""The detector's properties: where it stands, how it listens, how noisy it is.

``ReceiverSpec`` is the one schema of a receiver (``spinviz.analysis.receiver`` computes with
it); a scene's ``[observe]`` table takes the same keys with the same types (``DETECTOR_KEYS``),
and the command line's overrides are checked by it.

Defaults: a laboratory setup for a crystal spinning at GHz in a cryogenic trap, stated in the
documentation's "Designing an experiment" as assumptions:

* ``distance_cm`` = 10: an antenna 10 cm from the crystal (outside a trap's electrodes, inside
  the cryostat's radiation shield);
* ``antenna_gain_dbi`` = 5: a small dual-polarized antenna (a crossed-dipole or patch feed);
  both polarizations are received, so the collected power is the flux times the effective
  area lambda^2 G / 4 pi;
* ``noise_temperature_k`` = 5: a cryogenic HEMT amplifier at 4 K, system noise included;
* ``bandwidth_hz`` = 1 MHz: the receiver's instantaneous band, retuned to follow the line
  between integrations;
* ``integration_s`` = 1: the length of one estimate of the line's frequency, power and
  polarization.
"""

from __future__ import annotations

import math
from typing import Annotated

from pydantic import model_validator

from .. import units as U
from ..errors import SpecError
from .base import Real, between, request

DISTANCE_CM = (1e-4, 1e30, "from a micron to a megaparsec")
Distance = Annotated[Real, between(*DISTANCE_CM)]
Bandwidth = Annotated[Real, between(1.0, 1e12, "Hz")]
Integration = Annotated[Real, between(1e-6, 1e10, "s")]
NoiseTemperature = Annotated[Real, between(1e-3, 1e7, "K")]
NoiseDensity = Annotated[Real, between(1e-30, 1e-10, "W/Hz")]
GainDbi = Annotated[Real, between(-30.0, 90.0, "dBi")]
AreaCm2 = Annotated[Real, between(1e-6, 1e12, "cm^2")]

DEFAULT_DISTANCE_CM = 10.0
DEFAULT_BANDWIDTH_HZ = 1e6
DEFAULT_INTEGRATION_S = 1.0
DEFAULT_NOISE_TEMPERATURE_K = 5.0
DEFAULT_GAIN_DBI = 5.0

# why [observe] refuses fixed resolution thresholds (power_factor, frequency_resolution, polarization_deg)
RESOLUTION_COMPUTED = ("the resolutions are computed from the receiver (distance_cm, bandwidth_hz, integration_s, "
                       "the noise and antenna keys); observe reports the parting times across resolutions")

# the keys of [observe] that describe the detector (the same names as ReceiverSpec's fields)
DETECTOR_KEYS = ("distance_cm", "bandwidth_hz", "integration_s", "noise_temperature_k", "noise_density_w_per_hz",
                 "antenna_gain_dbi", "antenna_area_cm2")
# of each pair, one is given: an override of one replaces the scene's other
_PAIRS = (("noise_temperature_k", "noise_density_w_per_hz"), ("antenna_gain_dbi", "antenna_area_cm2"))


@request
class ReceiverSpec:
    """A receiver of the crystal's lines.

    distance_cm : from the crystal to the antenna; bandwidth_hz : instantaneous band;
    integration_s : the length of one estimate; noise_temperature_k (system) or
    noise_density_w_per_hz (one-sided N0), at most one, default 5 K; antenna_gain_dbi
    (constant over the band) or antenna_area_cm2 (effective area, both polarizations), at most
    one, default 5 dBi.
    """

    distance_cm: Distance = DEFAULT_DISTANCE_CM
    bandwidth_hz: Bandwidth = DEFAULT_BANDWIDTH_HZ
    integration_s: Integration = DEFAULT_INTEGRATION_S
    noise_temperature_k: NoiseTemperature | None = None
    noise_density_w_per_hz: NoiseDensity | None = None
    antenna_gain_dbi: GainDbi | None = None
    antenna_area_cm2: AreaCm2 | None = None

    @model_validator(mode="after")
    def _one_each(self):
        for pair in (("noise_temperature_k", "noise_density_w_per_hz"), ("antenna_gain_dbi", "antenna_area_cm2")):
            if all(getattr(self, k) is not None for k in pair):
                raise SpecError(pair[1], f"give only one of {', '.join(pair)}")
        return self

    @property
    def noise_density(self) -> float:
        """N0, the one-sided noise spectral density per polarization channel, erg (erg/s per Hz)."""
        if self.noise_density_w_per_hz is not None:
            return float(U.erg_per_s_from_w(self.noise_density_w_per_hz))
        t = DEFAULT_NOISE_TEMPERATURE_K if self.noise_temperature_k is None else self.noise_temperature_k
        return float(U.noise_density_from_temperature(t))

    def effective_area_cm2(self, f_hz):
        """The antenna's effective area at f Hz, cm^2: the given area, or G lambda^2 / 4 pi."""
        if self.antenna_area_cm2 is not None:
            return self.antenna_area_cm2 + 0.0 * U.wavelength_cm(f_hz)
        g = U.gain_from_dbi(DEFAULT_GAIN_DBI if self.antenna_gain_dbi is None else self.antenna_gain_dbi)
        return g * U.wavelength_cm(f_hz) ** 2 / (4.0 * math.pi)

    def describe(self) -> str:
        """The receiver in one line, for reports."""
        if self.noise_density_w_per_hz is not None:
            noise = f"N0 = {self.noise_density_w_per_hz:.3g} W/Hz"
        else:
            noise = f"T_sys = {DEFAULT_NOISE_TEMPERATURE_K if self.noise_temperature_k is None else self.noise_temperature_k:g} K"
        if self.antenna_area_cm2 is not None:
            antenna = f"effective area {self.antenna_area_cm2:g} cm^2"
        else:
            antenna = f"gain {DEFAULT_GAIN_DBI if self.antenna_gain_dbi is None else self.antenna_gain_dbi:g} dBi"
        return (f"antenna at {self.distance_cm:g} cm, {antenna}, both polarizations; {noise}; "
                f"band {self.bandwidth_hz:.3g} Hz; {self.integration_s:g} s per estimate")

    def with_options(self, **given) -> ReceiverSpec:
        """This receiver with the values given (keys of ``DETECTOR_KEYS``; None: not given) in
        place of its own, checked by this schema (``SpecError`` naming the key); a value for one
        of a pair (noise temperature or density, gain or area) replaces the other."""
        unknown = sorted(set(given) - set(DETECTOR_KEYS))
        if unknown:
            raise SpecError(unknown[0], f"not a receiver key; valid: {', '.join(DETECTOR_KEYS)}")
        given = {k: v for k, v in given.items() if v is not None}
        if not given:
            return self
        values = {k: getattr(self, k) for k in DETECTOR_KEYS}
        for pair in _PAIRS:
            for k in pair:
                if k in given:
                    values.update({o: None for o in pair if o != k})
        return ReceiverSpec(**{**values, **given})

    def record(self) -> dict:
        """The receiver's settings as plain numbers (JSON), with the defaults filled in."""
        return {"distance_cm": self.distance_cm, "bandwidth_hz": self.bandwidth_hz, "integration_s": self.integration_s,
                "noise_density_erg": self.noise_density,
                "noise_temperature_k": (None if self.noise_density_w_per_hz is not None else
                                        DEFAULT_NOISE_TEMPERATURE_K if self.noise_temperature_k is None
                                        else self.noise_temperature_k),
                "antenna_gain_dbi": (None if self.antenna_area_cm2 is not None else
                                     DEFAULT_GAIN_DBI if self.antenna_gain_dbi is None else self.antenna_gain_dbi),
                "antenna_area_cm2": self.antenna_area_cm2}
