"""The small two-model atlas spec the cluster and fault tests share (36 runs, tau to 1e8), the
per-run variables its store must hold, and the small refined spec the store's tests share
(4 x 3 cells x 2 members and one refinement level: 104 runs to tau = 1e6, ~3 s)."""

SPEC = """title = "fault test"
models = ["reduced", "truncated"]
[grid]
delta = [-0.6, 0.5]
chi_deg = [22.0, 45.0, 70.0]
[members]
count = 3
seed = 5
omega = 0.05
[run]
tau_end = 1e8
"""
VARIABLES = ("regime", "regime_early", "candidate", "status", "method", "confidence", "tau_reached", "nsteps", "nfev",
             "reason", "evidence", "omega_final", "done", "omega0", "paper")

REFINED = """title = "refined store test"
models = ["reduced"]
[grid]
delta = { min = -1.0, max = 1.0, cells = 4 }
chi_deg = { min = 0.0, max = 90.0, cells = 3 }
[members]
count = 2
seed = SEED
omega = 0.04
[run]
tau_end = 1e6
[refine]
levels = 1
"""


def refined_spec(seed: int = 3) -> str:
    """The refined spec's text with its starts drawn from ``seed`` (another seed: another atlas)."""
    return REFINED.replace("SEED", str(seed))
