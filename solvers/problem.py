"""What a thermoelastic problem on a named mesh is: materials per region, thermal
conditions per boundary, lumped fluid volumes, supports, probes. Everything refers to
the mesh's regions, boundaries and points by name; values that vary in time are
:class:`~gatetherm.solvers.expr.Value` expressions of the run's inputs.

A case file (``gatetherm run``) is read into a :class:`Problem`; the paper's frame is
one too (:func:`gatetherm.frame.problem.frame_problem`).
"""
from __future__ import annotations

from dataclasses import dataclass, field

from gatetherm.solvers.expr import Value
from gatetherm.solvers.scheme import TimeScheme
from gatetherm.solvers.material import Material

AXES = "xyz"


@dataclass(frozen=True)
class Film:
    """Convection from a boundary to an ambient: ``q = h (T − ambient)``."""

    boundary: str
    h: float
    """Film coefficient, W/(m² K) (with a :attr:`law`: the reference coefficient of the matrix)."""
    ambient: Value
    """Ambient temperature, °C."""
    law: object = None
    """A :class:`~gatetherm.solvers.convection.FilmLaw` (a correlation, radiation) that gives the
    coefficient from the surface temperature and the inputs; None: the constant :attr:`h`."""


@dataclass(frozen=True)
class FixedTemperature:
    """A boundary held at a temperature."""

    boundary: str
    value: Value
    """Temperature, °C."""


@dataclass(frozen=True)
class Flux:
    """A heat flux into the solid through a boundary."""

    boundary: str
    value: Value
    """Heat flux density into the solid, W/m²."""


@dataclass(frozen=True)
class Source:
    """A volumetric heat source in a region."""

    region: str
    density: Value
    """Power density, W/m³ (times :attr:`per`)."""
    per: float = 1.0
    """The density is ``per × density``: 1 for a density, 1/volume (1/m³) for a power (W) in the region."""
    loss: str = ""
    """The output column that reports its power over time (a machine element's loss, W), empty: none."""
    on_boundary: bool = False
    """The source lies on the boundary named :attr:`region` (a surface source: :attr:`density` is its
    power, W, spread over the boundary's area or its band)."""
    position: Value | None = None
    """A source that moves: the centre of the band its power is spread over, m along :attr:`direction`
    (None: spread over the whole region)."""
    direction: tuple[float, ...] = ()
    """Unit vector along which :attr:`position` and :attr:`length` are measured."""
    length: float = 0.0
    """Extent of the band along the direction, m."""
    parts: tuple = ()
    """Values inside a machine element's loss that read the schedule and have a range of their own
    (a viscosity > 0), checked at the schedule's samples as every value is: the loss's formula
    alone would hide them (|ν n|)."""


@dataclass(frozen=True)
class FaceFilm:
    """2-D only: convection from the front and back faces of the section (both faces, per
    unit of section area) to an ambient."""

    h: float
    """Film coefficient of each face, W/(m² K)."""
    ambient: Value
    """Ambient temperature, °C."""


@dataclass(frozen=True)
class Fluid:
    """A lumped, well-mixed fluid volume wetting a boundary (an oil tank), fed through an
    optional supply hose (one more lump) while its pump runs."""

    name: str
    """Its temperature is reported as ``T_<name>_degC``."""
    boundary: str
    """The wetted boundary."""
    capacity: float
    """Heat capacity of the fluid in the volume, J/K."""
    film_on: float
    """Wall film coefficient while the pump runs, W/(m² K)."""
    film_off: float
    """Wall film coefficient of standing fluid, W/(m² K)."""
    conductance: float
    """Enthalpy flow of the supply while the pump runs, ρc·Q, W/K."""
    supply: Value
    """Temperature of the supplied fluid, °C."""
    pump: Value
    """Pump state: on where > 0.5."""
    hose_capacity: float = 0.0
    """Heat capacity of the supply hose and its fluid, J/K (0: no hose)."""
    hose_loss: float = 0.0
    """Heat loss of the hose to the ambient, W/K."""
    ambient: Value = Value(0.0)
    """Ambient of the hose, °C."""
    hose_name: str = ""
    """Name of the hose temperature in the outputs (default ``<name>_hose``)."""


@dataclass(frozen=True)
class Support:
    """Displacement components of a boundary (or, in 3-D, of a line) held at zero or at a
    prescribed displacement, or an elastic foundation."""

    boundary: str
    components: tuple[int, ...]
    """Displacement components (0 = x, 1 = y, 2 = z) concerned."""
    stiffness: float | None = None
    """Foundation stiffness per unit area, N/m³ (None: the components are fixed)."""
    values: tuple[Value, ...] = ()
    """Prescribed displacement of each of ``components``, m (empty: held at zero)."""


@dataclass(frozen=True)
class BoundaryLoad:
    """A mechanical load on a boundary: a pressure, a traction or a total force."""

    boundary: str
    kind: str
    """"pressure" (one value, Pa, positive into the body), "traction" (per component, Pa)
    or "force" (per component, N: the total, spread uniformly over the boundary's area)."""
    values: tuple[Value, ...]


@dataclass(frozen=True)
class PointLoad:
    """A force on the node of a point group."""

    point: str
    force: tuple[Value, ...]
    """Force per component, N."""


@dataclass(frozen=True)
class Contact:
    """Two regions touching on their interface (the boundary ``"A/B"``, names sorted): a
    thermal contact conductance and, with ``stiffness``, an elastic joint layer instead of a
    perfect bond."""

    name: str
    between: tuple[str, str]
    conductance: float | None = None
    """Contact conductance, W/(m² K) (None: no heat solve)."""
    stiffness: tuple[float, float] | None = None
    """Normal and tangential stiffness per unit area, N/m³ (None: bonded)."""

    @property
    def boundary(self) -> str:
        return "/".join(sorted(self.between))


@dataclass(frozen=True)
class Probe:
    """A named point and what is reported there."""

    name: str
    xyz: tuple[float, ...]
    """Coordinates, m."""
    quantities: tuple[str, ...] = ("T",)
    """Any of "T" (temperature), "u" (displacement components), "sigma" (stress components
    and von Mises)."""
    region: str | None = None
    """Recover the stress from this region's elements only (None: all)."""


@dataclass(frozen=True)
class Relative:
    """The displacement of probe ``a`` minus that of probe ``b`` along an axis."""

    name: str
    a: str
    b: str
    axis: int
    """0 = x, 1 = y, 2 = z."""


@dataclass(frozen=True)
class Signals:
    """Which outputs are the data format's θ_A, θ_B, θ_C and δ (compensate, diagnose)."""

    theta_A: str | None = None
    """Probe of θ_A."""
    theta_B: str | None = None
    """Probe of θ_B."""
    theta_C: tuple[str, ...] = ()
    """Probes whose mean is θ_C."""
    delta: str | None = None
    """Relative displacement that is δ."""

    @property
    def complete(self) -> bool:
        return bool(self.theta_A and self.theta_B and self.theta_C and self.delta)


@dataclass(frozen=True)
class Problem:
    """A thermoelastic problem on a mesh with named groups."""

    dim: int
    materials: dict[str, Material]
    """Material of every region, by region name."""
    order: int = 1
    """Polynomial degree of temperature and displacement (1 or 2)."""
    thickness: dict[str, float] = field(default_factory=dict)
    """2-D: out-of-plane thickness by region, m (default 1)."""
    plane: str = "stress"
    """2-D: "stress", "strain" or "axisymmetric" (x = r ≥ 0, y = z; every integral over the
    full revolution)."""
    T0: float = 20.0
    """Initial temperature of solid and fluids, °C."""
    T_ref: float = 20.0
    """Stress-free temperature, °C."""
    films: tuple[Film, ...] = ()
    fixed: tuple[FixedTemperature, ...] = ()
    fluxes: tuple[Flux, ...] = ()
    sources: tuple[Source, ...] = ()
    faces: FaceFilm | None = None
    fluids: tuple[Fluid, ...] = ()
    supports: tuple[Support, ...] = ()
    probes: tuple[Probe, ...] = ()
    relative: tuple[Relative, ...] = ()
    means: tuple[tuple[str, str], ...] = ()
    """(name, boundary): the area-mean temperature of a boundary, reported as ``T_<name>_degC``."""
    signals: Signals = Signals()
    prescribed: Value | None = None
    """A temperature field (°C, an expression of x, y, z) instead of a heat solve."""
    prescribed_regions: dict[str, float] = field(default_factory=dict)
    """A temperature per region (°C) instead of a heat solve (may jump between regions)."""
    elastic: bool = True
    """Solve the thermoelastic problem (needs E, ν, α of every region and supports)."""
    scheme: TimeScheme = TimeScheme()
    """Time stepping of a transient heat solve."""
    gravity: tuple[Value, ...] = ()
    """Acceleration of gravity per component, m/s² (the body force ρ g; empty: none)."""
    loads: tuple[BoundaryLoad, ...] = ()
    point_loads: tuple[PointLoad, ...] = ()
    contacts: tuple[Contact, ...] = ()
    thermal: bool = True
    """False: a purely mechanical problem (no temperature, no thermal strain)."""

    @property
    def heat(self) -> bool:
        """The temperature is solved for (not prescribed, not absent)."""
        return self.thermal and self.prescribed is None and not self.prescribed_regions

    @property
    def axisymmetric(self) -> bool:
        return self.dim == 2 and self.plane == "axisymmetric"


def values(problem: Problem) -> list[Value]:
    """The values of the problem's conditions, sources and fluids (the ones a run evaluates)."""
    out = [f.ambient for f in problem.films] + [f.value for f in (*problem.fixed, *problem.fluxes)]
    out += [v for s in problem.sources for v in s.parts]  # before the losses they make: the named cause first
    out += [s.density for s in problem.sources] + ([problem.faces.ambient] if problem.faces else [])
    out += [s.position for s in problem.sources if s.position is not None]
    out += [f.law.speed for f in problem.films if f.law is not None]  # a correlation's speed
    out += [v for f in problem.fluids for v in (f.supply, f.pump, f.ambient)]
    out += [*problem.gravity, *(v for x in (*problem.loads, *problem.supports) for v in x.values)]
    return out + [v for pl in problem.point_loads for v in pl.force]


def inputs(problem: Problem) -> set[str]:
    """The schedule columns the problem's values read (not time ``t``)."""
    return set().union(*(v.names() for v in values(problem))) - {"t"}
