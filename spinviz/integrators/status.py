"""Status codes shared by the compiled kernels and their Python wrappers, and what they mean."""

OK, TOO_MANY_STEPS, STEP_UNDERFLOW, NOT_FINITE, STIFF, TURN_TOO_LARGE, INTERRUPTED = 0, 1, 2, 3, 4, 5, 6

STOP_POLL = 256          # the compiled loops look at their stop flag every this many steps

MESSAGES = {
    TOO_MANY_STEPS: "exceeded the step limit",
    STEP_UNDERFLOW: "step size fell below round-off (the problem is too stiff for an explicit method)",
    NOT_FINITE: "the solution left the finite numbers (overflow)",
    STIFF: "stiffness detected (Hairer's test: 15 steps in a row limited by stability)",
    TURN_TOO_LARGE: "a step turns the body by more than half a turn (exponential coordinates are singular "
                    "at a full turn); use a smaller step",
    INTERRUPTED: "interrupted",
}

MODEL_ID = {"free": 0, "reduced": 1, "truncated": 2}
