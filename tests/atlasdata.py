"""The small two-model atlas spec the cluster and fault tests share (36 runs, tau to 1e8), and
the per-run variables its store must hold."""

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
