"""Helpers that shape the workbench chapter's results for display: the effects a loop added, one row per
step, and the library's conventions on one worked example.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from ...angles import DEG, heading_deg
from ...sensors.trajectory import euler_to_dcm
from ...workbench.loop import LoopResult
from ...workbench.magnetometer import QUAT, body_from_nav


def added(result: LoopResult) -> str:
    """The effects a loop added, in order."""
    return ", ".join(d.missing for d in result.diagnoses[:-1]) or "-"


def steps_frame(result: LoopResult, label: str = "") -> pd.DataFrame:
    """One row per step of a loop: model, rms, held-out rms, effect named (unit in the headers)."""
    t = result.steps_table().reset_index()
    if label:
        t.insert(0, "data", label)
    return t


def conventions_example() -> pd.DataFrame:
    """The library's heading and rotation conventions on one worked example, computed by navlib: the
    quaternion of a 90 deg yaw (scalar first, rotating body FRD into NED, as the ``magnetometer`` systems
    and BROAD's files use it), the body's forward axis it turns into NED, the body field a level compass
    sees there and its heading (:func:`navlib.angles.heading_deg`, deg clockwise from north), and the same
    turn in paper E's convention (:mod:`navlib.sensors.trajectory`: yaw in rad counter-clockwise from north,
    body x right, y forward, z up, navigation frame ENU), whose forward axis it also turns east."""
    yaw = 90.0
    q = np.array([np.cos(yaw * DEG / 2), 0.0, 0.0, np.sin(yaw * DEG / 2)])
    C_nb = body_from_nav(pd.DataFrame([q], columns=list(QUAT)))[0]  # NED -> body
    forward_ned = C_nb.T @ np.array([1.0, 0.0, 0.0])
    field_ned = np.array([20.0, 0.0, 40.0])  # north and down, uT
    field_body = C_nb @ field_ned
    e_yaw = -yaw * DEG  # the same turn, paper E's way
    e_forward = euler_to_dcm(np.array([0.0, 0.0, e_yaw])) @ np.array([0.0, 1.0, 0.0])  # C_b^n, ENU
    rows = [
        ("yaw (compass, workbench, BROAD)", f"{yaw:g} deg, clockwise from north (east of north)"),
        ("quaternion q_w, q_x, q_y, q_z", ", ".join(f"{v:.4f}" for v in q)),
        (
            "body x (forward) in NED",
            ", ".join(f"{v:+.3f}" for v in forward_ned) + "  (points east)",
        ),
        (
            "field N, E, D = 20, 0, 40 uT seen in body axes",
            ", ".join(f"{v:+.2f}" for v in field_body),
        ),
        (
            "compass heading atan2(-m_y, m_x)",
            f"{float(heading_deg(field_body[0], field_body[1])):.1f} deg",
        ),
        ("paper E's yaw (rad, counter-clockwise, ENU)", f"{e_yaw:+.4f} rad"),
        (
            "paper E: body y (forward) in ENU",
            ", ".join(f"{v:+.3f}" for v in e_forward) + "  (points east)",
        ),
    ]
    return pd.DataFrame(rows, columns=["quantity", "value"]).set_index("quantity")
