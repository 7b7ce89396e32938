"""Plain records the bindings return (named tuples: fields by name or by
position; all values are copies)."""

import collections

Event = collections.namedtuple("Event", "kind i j time strain")
Event.__doc__ = """One event (odhs_event): kind (EventKind), the pair i < j (j = N + w for wall w),
the physical time and the accumulated strain at the event."""

StepInfo = collections.namedtuple(
    "StepInfo", "kind i j event_time event_strain collisions openings time_start time_end strain_start "
                "strain_end advanced driver_change")
StepInfo.__doc__ = """What one step did (odhs_step_info, Stepper.step_ex): the first event (kind,
i, j, event_time, event_strain; kind NONE when there was none), the numbers of collisions and
openings, time and strain at the start and end, advanced (the time moved) and driver_change (the
step only applied a change of the driver)."""

Counts = collections.namedtuple("Counts", "steps collisions openings")
Counts.__doc__ = "Stepper counters (odhs_stepper_counts)."

Settings = collections.namedtuple("Settings", "integrator dt tolerance correction_interval")
Settings.__doc__ = "Integration settings in force (odhs_stepper_get_settings)."

RunLimits = collections.namedtuple("RunLimits", "max_steps stall_steps")
RunLimits.__doc__ = "Guards of the run calls (odhs_stepper_get_run_limits); 0 = no cap / disabled."

AdaptiveStats = collections.namedtuple("AdaptiveStats", "rejected h")
AdaptiveStats.__doc__ = "Adaptive-integrator counters: rejected steps and the current step h in units of tau."
BatchedStats = collections.namedtuple("BatchedStats", "batched_steps exact_steps solves")
BatchedStats.__doc__ = ("Batched-integrator counters: accepted batched steps, steps taken by the exact scheme instead, "
                        "force solves of the steps' contact problems.")

CorrectionStats = collections.namedtuple("CorrectionStats", "corrections passes closed")
CorrectionStats.__doc__ = ("Drift-correction counters: corrections applied, their passes (one force solve each), pairs "
                           "the passes closed.")

Errors = collections.namedtuple("Errors", "contact_gap overlap")
Errors.__doc__ = """Largest |gap|/(a_i+a_j) over contacts and largest overlap -gap/(a_i+a_j) over all
pairs (odhs_stepper_errors)."""

Contacts = collections.namedtuple("Contacts", "i j kind force gap")
Contacts.__doc__ = """The contacts as arrays of Nc entries (copies): i, j (uintp, i < j; j = N + w for
wall w), kind (intc, ContactKind values), force (float64, >= 0 on a valid network) and gap
(float64, r - a_i - a_j)."""

Constrained = collections.namedtuple("Constrained", "n_backbone n_contacts in_subset zbar_num")
Constrained.__doc__ = """The constrained subset (odhs_network_constrained): its size Nbar, the number
of contacts inside it, in_subset (n,) bool flags and zbar_num (zbar = zbar_num / Nbar)."""

Certificate = collections.namedtuple(
    "Certificate", "jammed isostatic phi pressure n_particles n_rattlers n_backbone n_contacts "
                   "n_contacts_backbone n_contacts_isostatic z z_backbone force_balance gap_error overlap "
                   "min_force n_pivots")
Certificate.__doc__ = """A jamming certificate (odhs_jam_certificate, jamming.h): jammed and isostatic
(bool), phi, pressure, counts, z, z_backbone, and the errors relative to the mean backbone force
or the contact distance (force_balance, gap_error, overlap, min_force), n_pivots."""

JamLpReport = collections.namedtuple(
    "JamLpReport",
    "n_lps simplex_iterations rows_max phi_lp growth_last end_steps shakes polishes quench_iterations phi_start "
    "quench_steps")
JamLpReport.__doc__ = """What Stepper.jam_lp did (odhs_jam_lp_report, jamming.h): the linear programmes solved,
their simplex iterations, the largest number of pair constraints, phi at the end of the chain,
sqrt(Gamma) - 1 of the last programme, the event-driven steps of the end game, the degenerate
packings shaken and jammed again, the extra polishes of the contact gaps, the FIRE iterations of the
quench start (0 without it), phi where the chain started, and the rescalings of the quench toward
phi_J (since 0.2.11)."""

Propulsion = collections.namedtuple("Propulsion", "forces switch_times")
Propulsion.__doc__ = """Current self-propulsion forces (n, dim) and next switch times (n,), or None
for switch times before a stepper started the clock."""

OscillatoryShear = collections.namedtuple("OscillatoryShear", "shape amplitude period t0")
OscillatoryShear.__doc__ = "Settings of oscillatory shear (odhs_driver_get_oscillatory_shear)."

SoftcoreCounts = collections.namedtuple("SoftcoreCounts", "steps force_evals min_iterations")
SoftcoreCounts.__doc__ = "Soft-core counters (odhs_softcore_counts)."

SolverInfo = collections.namedtuple("SolverInfo", "name installed")
SolverInfo.__doc__ = "A built-in solver name and whether this library was built with it (odhs_solver_list)."
