"""The library's pinned enumerations as Python IntEnums (values from the
headers, read from the compiled module), with helpers that also accept their
names as strings ("heun", "collision", "RD0")."""

import enum

from ._core import lib


class EventKind(enum.IntEnum):
    """Event kinds (ODHS_EVENT_*)."""

    NONE = lib.ODHS_EVENT_NONE
    COLLISION = lib.ODHS_EVENT_COLLISION  # a new contact formed
    OPENING = lib.ODHS_EVENT_OPENING  # a contact opened (its force reached zero)


class ContactKind(enum.IntEnum):
    """Contact kinds (ODHS_CONTACT_*)."""

    TEMPORARY = lib.ODHS_CONTACT_TEMPORARY
    PERMANENT = lib.ODHS_CONTACT_PERMANENT  # a bond of a composite particle
    WALL = lib.ODHS_CONTACT_WALL  # particle i against wall j - N


class Integrator(enum.IntEnum):
    """Stepper integrators (ODHS_INTEGRATOR_*)."""

    EULER = lib.ODHS_INTEGRATOR_EULER  # the paper's explicit Euler with a fixed step
    HEUN = lib.ODHS_INTEGRATOR_HEUN  # adaptive Heun (the default)
    BATCHED = lib.ODHS_INTEGRATOR_BATCHED  # batched events: steps not cut at collisions (large N)


class Oscillation(enum.IntEnum):
    """Shapes of oscillatory shear (ODHS_OSCILLATION_*)."""

    SINE = lib.ODHS_OSCILLATION_SINE
    TRIANGLE = lib.ODHS_OSCILLATION_TRIANGLE


class Feature(enum.IntEnum):
    """Optional stepper features (ODHS_FEATURE_*), for Stepper.feature_work."""

    PRESSURE = lib.ODHS_FEATURE_PRESSURE
    COMPOSITE = lib.ODHS_FEATURE_COMPOSITE
    WALLS = lib.ODHS_FEATURE_WALLS


class WallShape(enum.IntEnum):
    """Wall shapes (ODHS_WALL_*)."""

    PLANE = lib.ODHS_WALL_PLANE
    SPHERE = lib.ODHS_WALL_SPHERE
    SEGMENT = lib.ODHS_WALL_SEGMENT


class TrajFormat(enum.IntEnum):
    """Trajectory formats (ODHS_TRAJ_*)."""

    XYZ = lib.ODHS_TRAJ_XYZ
    LAMMPS_DUMP = lib.ODHS_TRAJ_LAMMPS_DUMP
    LAMMPS_LOCAL = lib.ODHS_TRAJ_LAMMPS_LOCAL


class SoftcoreModel(enum.IntEnum):
    """Soft-core models (ODHS_SOFTCORE_RD0 ... CDT)."""

    RD0 = lib.ODHS_SOFTCORE_RD0
    CD0 = lib.ODHS_SOFTCORE_CD0
    RD = lib.ODHS_SOFTCORE_RD
    CD = lib.ODHS_SOFTCORE_CD
    CDN = lib.ODHS_SOFTCORE_CDN
    CDT = lib.ODHS_SOFTCORE_CDT


class SoftcoreIntegrator(enum.IntEnum):
    """Integrators of the overdamped soft-core models."""

    FIXED = lib.ODHS_SOFTCORE_FIXED
    ADAPTIVE = lib.ODHS_SOFTCORE_ADAPTIVE


class Minimiser(enum.IntEnum):
    """Soft-core energy minimisers (ODHS_SOFTCORE_SD, FIRE, CG)."""

    SD = lib.ODHS_SOFTCORE_SD
    FIRE = lib.ODHS_SOFTCORE_FIRE
    CG = lib.ODHS_SOFTCORE_CG


class StressPart(enum.IntEnum):
    """Parts of the soft-core stress tensor (ODHS_SOFTCORE_STRESS_*)."""

    TOTAL = lib.ODHS_SOFTCORE_STRESS_TOTAL
    ELASTIC = lib.ODHS_SOFTCORE_STRESS_ELASTIC
    DISSIPATIVE = lib.ODHS_SOFTCORE_STRESS_DISSIPATIVE
    KINETIC = lib.ODHS_SOFTCORE_STRESS_KINETIC


class SolverFlag(enum.IntFlag):
    """Capability flags of a solver backend (ODHS_SOLVER_*)."""

    ITERATIVE = lib.ODHS_SOLVER_ITERATIVE
    DIRECT = lib.ODHS_SOLVER_DIRECT
    USES_GUESS = lib.ODHS_SOLVER_USES_GUESS
    LEAST_SQUARES = lib.ODHS_SOLVER_LEAST_SQUARES


def to_enum(cls, value, what):
    """value (a member, its int value or its name in any case, '-' and '_'
    alike) as a member of the IntEnum cls. An int that is no member is
    returned as it is, for the library to judge (it raises InvalidError)."""
    if isinstance(value, str):
        key = value.strip().upper().replace("-", "_")
        try:
            return cls[key]
        except KeyError:
            raise ValueError("unknown %s %r (one of %s)" % (what, value, ", ".join(m.name.lower() for m in cls))) \
                from None
    try:
        return cls(value)
    except ValueError:
        return int(value)
