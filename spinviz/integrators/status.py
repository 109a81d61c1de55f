"""Status codes shared by the compiled kernels and their Python wrappers, and what they mean."""

OK, TOO_MANY_STEPS, STEP_UNDERFLOW, NOT_FINITE, STIFF, TURN_TOO_LARGE, INTERRUPTED, RUNAWAY = 0, 1, 2, 3, 4, 5, 6, 7
# stopped by an event where the end state is known (the atlas's early stop), and a truncated
# start refused before any step (codes as the atlas store has always written them)
STOPPED_RESIDUAL, SINGULAR_START = 10, 11

STOP_POLL = 256          # the compiled loops look at their stop flag every this many steps

MESSAGES = {
    TOO_MANY_STEPS: "exceeded the step limit",
    STEP_UNDERFLOW: "step size fell below round-off (the problem is too stiff for an explicit method)",
    NOT_FINITE: "the solution left the finite numbers (overflow)",
    STIFF: "stiffness detected (Hairer's test: 15 steps in a row limited by stability)",
    TURN_TOO_LARGE: "a step turns the body by more than half a turn (exponential coordinates are singular "
                    "at a full turn); use a smaller step",
    INTERRUPTED: "interrupted",
    RUNAWAY: "the solution runs away",
    STOPPED_RESIDUAL: "stopped: residual rotation about d reached (the exact end state)",
    SINGULAR_START: "the truncated equation (2.5) is singular or nearly so at the start",
}

# A run stops as a runaway when tau0 |Omega| exceeds RUNAWAY_FACTOR x max(tau0 |Omega0|, 1): the
# reduction (2.3) that defines the model assumes tau0 |Omega| << 1, and past that point its
# solutions grow without bound (measured: |omega| ~ 1/(t* - t), a finite-time blow-up).
RUNAWAY_FACTOR = 10.0


def runaway_bound(eps: float) -> float:
    """The largest |omega| in spin units (|omega(0)| = 1, coupling |g|^2 = eps) before a run is
    called a runaway."""
    return RUNAWAY_FACTOR * max(1.0, 1.0 / eps) if eps > 0 else float("inf")
