"""The crank (class I mechanism) that drives a dyad: its driving torque and the
frame reaction at its pivot, from the dyad's reaction on the crank.

The crank p turns about the fixed pivot O. The dyad acts on it at D_n with
-R_np (and, where D_n slides on the crank, with the reactive moment -M^R_np).
With the crank's weight and d'Alembert inertia, its equilibrium gives

    forces about nothing:  R_O - R_np + m_c (g - a_Sc) = 0
    moments about O:       M_drive + (D_n - O) x (-R_np) - M^R_np
                           + (S_c - O) x m_c (g - a_Sc) - J_c eps_c = 0

so the driving (balancing) torque M_drive (N m) and the force R_O (N) of the
frame on the crank at O follow directly.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .geometry import cross

if TYPE_CHECKING:
    from .builtin import Mechanism


def balance(
    mechanism: Mechanism, kin: dict, r_np: np.ndarray, m_np: np.ndarray | None = None
) -> dict:
    """Driving torque and pivot reaction of the crank over the samples of `kin`.

    r_np: (N, 2) force on the dyad's link n from the crank at D_n (N);
    m_np: (N,) reactive moment on n from the crank (N m), where D_n slides on it.
    Returns {"torque": (N,) N m, counter-clockwise on the crank; "R_O": (N, 2) N,
    force of the frame on the crank at O}.
    """
    r_np = np.asarray(r_np, dtype=float)
    m_np = np.zeros(len(r_np)) if m_np is None else np.asarray(m_np, dtype=float)
    crank = mechanism.crank
    weight_and_inertia = crank["mass"] * (np.asarray(mechanism.gravity) - kin["a_S_c"])
    r_o = r_np - weight_and_inertia
    torque = -(
        cross(kin["D_n"] - kin["O"], -r_np)
        - m_np
        + cross(kin["S_c"] - kin["O"], weight_and_inertia)
        - crank["inertia"] * kin["crank.epsilon"]
    )
    return {"torque": torque, "R_O": r_o}


def kinetic_energy(mechanism: Mechanism, kin: dict) -> np.ndarray:
    """Kinetic energy (J) of crank and both dyad links."""
    params = mechanism.fmu_parameters()
    crank = mechanism.crank
    energy = (
        0.5 * crank["mass"] * np.sum(kin["v_S_c"] ** 2, axis=-1)
        + 0.5 * crank["inertia"] * kin["crank.omega"] ** 2
    )
    for g in ("m", "n"):
        energy = (
            energy
            + 0.5 * params[f"link_{g}.mass"] * np.sum(kin[f"v_S_{g}"] ** 2, axis=-1)
            + 0.5 * params[f"link_{g}.inertia"] * kin[f"{g}.omega"] ** 2
        )
    return energy


def load_power(mechanism: Mechanism, kin: dict) -> np.ndarray:
    """Power (W) of the active loads and of gravity on crank and links."""
    params = mechanism.fmu_parameters()
    g = np.asarray(mechanism.gravity)
    power = mechanism.crank["mass"] * kin["v_S_c"] @ g
    for link in ("m", "n"):
        power = (
            power
            + np.sum(kin[f"{link}.force"] * kin[f"v_S_{link}"], axis=-1)
            + kin[f"{link}.moment"] * kin[f"{link}.omega"]
            + params[f"link_{link}.mass"] * kin[f"v_S_{link}"] @ g
        )
    return power
