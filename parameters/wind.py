"""The scene's ``[wind]`` section: the wind's speed with height (operation/wind.py has
the law, forms/wind.py its UFL half in the helix's drag, Eq. 14).

How it relates to ``[environment]``: without ``wind.speed_m_s`` (the default) the
wind is environment.wind_speed_m_s, uniform, as in the paper.  With it, ``[wind]`` is
the wind: environment.wind_speed_m_s must then be 0 (absent) or the same speed with the
uniform profile (the same wind said twice); a scene giving both otherwise is refused.
``wind.air_density_kg_m3``, when given, is the air's density for the helix's drag and
the rotor alike, and environment.air_density_kg_m3 must be absent or agree.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path

from rawehelix.operation.wind import FLOOR_M, PROFILES, UNIFORM
from rawehelix.parameters import wind_time
from rawehelix.parameters.checks import ParameterError, _non_negative, _positive

DEFAULT_AIR_DENSITY = 1.225  # environment.air_density_kg_m3's default [kg/m^3]


@dataclass(frozen=True)
class Wind:
    """The wind V(z) along -i_E (operation/wind.py)."""

    # V_ref, the wind's speed at the reference height; absent: environment.wind_speed_m_s,
    # uniform (the paper's) [m/s]
    speed_m_s: float | None = None
    reference_height_m: float = 10.0  # z_ref, above the helix's ground end [m]
    # V(z): "uniform" (V_ref), "power" (V_ref (z/z_ref)^a) or "log" (V_ref ln(z/z0) / ln(z_ref/z0))
    profile: str = "uniform"
    shear_exponent: float = 0.14  # a of profile "power" [-]
    roughness_m: float = 0.03  # z0 of profile "log" [m]
    # the air's density for the drag and the rotor; absent: environment.air_density_kg_m3 [kg/m^3]
    air_density_kg_m3: float | None = None
    # how the wind changes in time (operation/wind_series.py): "steady", "step" (to
    # step_to_m_s), "gust" (IEC 61400-1's extreme operating gust), "turbulent" (IEC
    # Kaimal spectrum and coherence, pyconturb) or "file" (a CSV of the hub's wind)
    kind: str = "steady"
    step_to_m_s: float | None = None  # "step": V_ref after the step [m/s]
    step_time_s: float = 10.0  # "step": the ramp's start [s]
    rise_time_s: float = 2.0  # "step": its rise time, a half-cosine ramp; 0 a jump [s]
    gust_start_s: float = 10.0  # "gust": the gust's start; it lasts 10.5 s [s]
    # "gust", "turbulent": IEC 61400-1's turbulence class, "A+", "A", "B" or "C"
    # (I_ref 0.18, 0.16, 0.14, 0.12)
    turbulence_class: str = "B"
    wind_class: str = "III"  # "gust": IEC's wind turbine class "I", "II", "III" (V_ref 50, 42.5, 37.5 m/s)
    # "gust", "turbulent": the hub's height above the ground end; absent: the top end's [m]
    hub_height_m: float | None = None
    seed: int = 0  # "turbulent": the random seed, 0 to 2^32 - 1
    # "turbulent": sigma_u / V_hub; absent: the class's, I_ref (0.75 V_hub + 5.6) / V_hub [-]
    turbulence_intensity: float | None = None
    duration_s: float = 600.0  # "turbulent": the series' length, >= time.until_s [s]
    time_step_s: float = 0.05  # "turbulent": its step (Nyquist 1 / (2 dt)) [s]
    # "file": a CSV of the hub's wind (its path relative to the scene file): the columns
    # time_s (uniform step) and speed_m_s, or u_m_s, v_m_s, w_m_s (along -x, lateral, up)
    file: str | None = None

    def __post_init__(self):
        if self.profile not in PROFILES:
            raise ParameterError("wind.profile", self.profile, f"must be one of {PROFILES}")
        if not self.active:
            given = [f.name for f in dataclasses.fields(self) if getattr(self, f.name) != f.default]
            if given:
                raise ParameterError("wind.speed_m_s", None,
                                     f"is required: [wind] gives wind.{given[0]} but no speed "
                                     "(or give the uniform wind as environment.wind_speed_m_s)")
            return
        _non_negative("wind", self, "speed_m_s", "shear_exponent")
        _positive("wind", self, "reference_height_m", "roughness_m")
        if self.air_density_kg_m3 is not None:
            _non_negative("wind", self, "air_density_kg_m3")
        if self.shear_exponent > 1:
            raise ParameterError("wind.shear_exponent", self.shear_exponent,
                                 "must lie in [0, 1] (1/7 over open land)")
        if not self.roughness_m < self.reference_height_m:
            raise ParameterError("wind.roughness_m", self.roughness_m,
                                 f"must be below wind.reference_height_m = "
                                 f"{self.reference_height_m!r} (the log law's ln(z_ref/z0) > 0)")
        wind_time.check_section(self)

    @classmethod
    def from_scene(cls, values: dict, folder: Path) -> "Wind":
        """The section as a scene gives it: ``file`` relative to the scene's ``folder``
        (studies/scene.py), kept as its absolute path."""
        name = values.get("file")
        if isinstance(name, str) and name and not Path(name).is_absolute():
            values = {**values, "file": str((folder / name).resolve())}
        return cls(**values)

    @property
    def series(self) -> dict:
        """kind "file": the file's columns, {time_s, and speed_m_s or u_m_s, v_m_s,
        w_m_s: numpy arrays} (read and checked once, at construction); None for the
        other kinds."""
        return getattr(self, "_series", None)

    @classmethod
    def reference_example(cls) -> "Wind":
        """A wind that is on, for the scene-key reference's probes
        (docs/_ext/rawehelix_reference.py): its ranges are met only with a speed."""
        return cls(speed_m_s=10.0, profile="power")

    @property
    def active(self) -> bool:
        return self.speed_m_s is not None

    @property
    def uniform(self) -> bool:
        """The same speed at every height (the paper's wind, or [wind]'s uniform one)."""
        return not self.active or self.profile == UNIFORM

    def describe(self) -> str:
        if not self.active:
            return "wind: environment.wind_speed_m_s, uniform (Eq. 14)"
        return f"wind: {self.profile}, {self.speed_m_s:g} m/s at {self.reference_height_m:g} m"


#: how the scene loader builds the section (studies/scene.py): a file beside the scene
read = Wind.from_scene

_L0 = ("helix.length_m",)
#: its normalised groups (parameters/scene.py::GROUP_KEYS): heights / L0; and the
#: groups its speed and density scale beside [environment]'s (replacing those entries)
GROUP_KEYS = {
    "nu": ("rho0 l_a L0^2 C_D/(2 M)", "Eq. 26",
           ("environment.air_density_kg_m3", "wind.air_density_kg_m3", "helix.drag_length_m",
            "helix.drag_coefficient"), ("helix.length_m", "helix.mass_kg")),
    "v_w0": ("v_w0/sqrt(g L0)", "Eq. 27", ("environment.wind_speed_m_s", "wind.speed_m_s"),
             ("helix.length_m", "environment.g_m_s2")),
    "wind_reference": ("z_ref/L0", "Eq. 14", ("wind.reference_height_m",), _L0),
    "wind_roughness": ("z0/L0", "Eq. 14", ("wind.roughness_m",), _L0),
}

#: where the section lives in a scene: Parameters.wind (the file's [wind]), a section of
#: the scene itself (HOLDER None), declared by Parameters
HOLDER, KEY, SECTION = None, "wind", Wind

#: its fields of Normalised, off (the uniform wind of v_w0): the profile, its exponent,
#: z_ref / L0, z0 / L0 and the power law's lowest height / L0 (forms/wind.py)
NORMALISED = {"wind_profile": "uniform", "wind_exponent": 0.0, "wind_reference": 1.0,
              "wind_roughness": 1.0, "wind_floor": 0.0}


def normalise(p, scales: dict) -> dict:
    """Normalised's wind fields: the heights over L0 (their values when off for the
    uniform wind)."""
    w = p.wind
    if w.uniform:
        return {**NORMALISED}
    L0 = scales["L0"]
    return {"wind_profile": w.profile, "wind_exponent": w.shear_exponent,
            "wind_reference": w.reference_height_m / L0, "wind_roughness": w.roughness_m / L0,
            "wind_floor": FLOOR_M / L0}


def check(params) -> None:
    """What [wind] cannot run with: another wind speed or air density in [environment]
    (one wind, said once), and a profile on the references' schemes (their drag is
    the paper's uniform wind)."""
    w, env = params.wind, params.environment
    if not w.active:
        return
    if env.wind_speed_m_s != 0 and not (w.profile == UNIFORM and env.wind_speed_m_s == w.speed_m_s):
        raise ParameterError("wind.speed_m_s", w.speed_m_s,
                             f"and environment.wind_speed_m_s = {env.wind_speed_m_s!r} both give "
                             "the wind: keep [wind] and remove environment.wind_speed_m_s")
    if (w.air_density_kg_m3 is not None and env.air_density_kg_m3 != DEFAULT_AIR_DENSITY
            and env.air_density_kg_m3 != w.air_density_kg_m3):
        raise ParameterError("wind.air_density_kg_m3", w.air_density_kg_m3,
                             f"and environment.air_density_kg_m3 = {env.air_density_kg_m3!r} "
                             "differ: give the air's density once")
    if w.profile != UNIFORM and params.discretisation.scheme != "fe":
        raise ParameterError("wind.profile", w.profile,
                             "is implemented by the FE scheme only (the references' drag is "
                             "the uniform wind of Eq. 14)")
    wind_time.check(params)
