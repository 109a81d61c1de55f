"""What the trap does to what the receiver sees (``spinviz observe``): at the start, the gas's
collisions per integration, the line's jump at one collision against the frequency resolution,
the gas's braking of the line against the radiation's, the line's walk over one integration,
and the static field's precession of L with the line shift it makes.

Numbers of ``physics.gas`` (the quadrature over the body's surface at the start's Omega) and of
``integrators.environment.field_precession``; the line is the rotation line at |L| / (2 pi I1),
so a collision's impulse J moves it by L_hat . J / (2 pi I1) and the field's precession of L
about E at Omega_p shifts it by Omega_p (E_hat . L_hat) / 2 pi.
"""

from __future__ import annotations

import math

import numpy as np

from .. import rotations as R


def report(sc, obs) -> dict:
    """The environment's numbers at the start of scene ``sc`` (CGS, ``[environment]`` active)
    for the receiver of ``obs`` (``observe.Observation``), as plain numbers (JSON)."""
    from ..integrators.environment import field_precession

    env = sc.environment
    body = sc.body
    w = np.asarray(sc.omega0, dtype=float)
    I = np.asarray(body.inertia, dtype=float)
    L = I * w
    Lh = L / np.linalg.norm(L)
    two_pi_I1 = 2.0 * math.pi * float(I[0])
    bg = obs.budgets[0] if obs.budgets else None
    i = int(np.argmax(bg.t > 0)) if bg is not None else 0
    f = float(np.linalg.norm(L)) / two_pi_I1
    sigma_f = float(bg.sigma_f[i]) if bg is not None else math.nan
    t_int = obs.receiver.integration_s if obs.receiver is not None else 1.0
    out = {"description": env.describe(), "at": "the start", "line_hz": f,
           "sigma_f_hz": sigma_f if math.isfinite(sigma_f) else None, "integration_s": t_int}
    # the radiation's braking of |L| at the start (the first model's torque, (2.2)+(2.3) or (2.5))
    from .. import units as U

    wd = U.omega_to_dimensionless(w, body.tau0)
    rad = np.asarray(body.system(sc.models[0]).radiation()(*wd), dtype=float) / body.tau0**2
    out["radiation_braking_per_s"] = float(-(Lh @ (I * rad)) / np.linalg.norm(L))
    gas = env.gas_model()
    if gas is not None:
        from ..physics.gas import GasModel
        from ..physics.surface import surface_of

        model = GasModel(gas, surface_of(body), tuple(body.inertia))
        rate, N, Q = model.moments(w)
        jump_mean = float(Lh @ N) / rate / two_pi_I1
        jump_rms = math.sqrt(float(Lh @ Q @ Lh) / rate) / two_pi_I1
        gamma = -float(Lh @ N) / float(np.linalg.norm(L))
        walk = math.sqrt(float(Lh @ Q @ Lh) * t_int) / two_pi_I1
        out.update({"collisions_per_s": rate, "collisions_per_integration": rate * t_int,
                    "jump_mean_hz": jump_mean, "jump_rms_hz": jump_rms,
                    "jump_rms_over_sigma_f": jump_rms / sigma_f if sigma_f > 0 else None,
                    "gas_braking_per_s": gamma,
                    "gas_over_radiation": (gamma / out["radiation_braking_per_s"]
                                           if out["radiation_braking_per_s"] else None),
                    "walk_per_integration_hz": walk, "mean_free_path_cm": gas.mean_free_path})
    if env.has_field:
        E = env.field_cgs()
        rate = field_precession(body, w, E)
        L_world = R.world_from_body(sc.q0, L)
        cos_EL = float(E @ L_world) / (float(np.linalg.norm(E)) * float(np.linalg.norm(L_world)))
        shift = rate * cos_EL / (2.0 * math.pi)
        out.update({"field_precession_rad_per_s": rate, "field_line_shift_hz": shift,
                    "field_line_shift_max_hz": rate / (2.0 * math.pi),
                    "field_shift_over_sigma_f": abs(shift) / sigma_f if sigma_f > 0 else None,
                    "field_shift_max_over_sigma_f": rate / (2.0 * math.pi) / sigma_f if sigma_f > 0 else None})
    return out


def lines(rep: dict) -> list[str]:
    """The report as lines for ``observe``'s table."""
    def g(x, fmt="{:.3g}"):
        return "-" if x is None else fmt.format(x)

    out = [f"the trap at the start: {rep['description']}"]
    if "collisions_per_s" in rep:
        out += [f"  collisions: {g(rep['collisions_per_s'])} per s, {g(rep['collisions_per_integration'])} per "
                f"{rep['integration_s']:g} s integration (mean free path {g(rep['mean_free_path_cm'])} cm)",
                f"  one collision moves the line by {g(rep['jump_rms_hz'])} Hz RMS (mean {g(rep['jump_mean_hz'])} Hz): "
                f"{g(rep['jump_rms_over_sigma_f'])} x the resolution sigma_f = {g(rep['sigma_f_hz'])} Hz",
                f"  the gas brakes the line at {g(rep['gas_braking_per_s'])} /s, the radiation at "
                f"{g(rep['radiation_braking_per_s'])} /s (gas / radiation = {g(rep['gas_over_radiation'])}); the "
                f"collisions walk it by {g(rep['walk_per_integration_hz'])} Hz per integration"]
    if "field_precession_rad_per_s" in rep:
        out.append(f"  the field turns L at {g(rep['field_precession_rad_per_s'])} rad/s: the line moves by "
                   f"{g(rep['field_line_shift_hz'])} Hz here, up to {g(rep['field_line_shift_max_hz'])} Hz with E along "
                   f"L ({g(rep['field_shift_max_over_sigma_f'])} x sigma_f)")
    return out + [""]
