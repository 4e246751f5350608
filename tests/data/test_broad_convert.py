"""The BROAD converter (navlib.data.broad) on small synthetic trial files in BROAD's layout (scipy.io.savemat):
frames, blocks, the chordal mean, flags, the level sweep, and bad input."""

import numpy as np
import pandas as pd
import pytest
from scipy.io import savemat
from scipy.spatial.transform import Rotation

from navlib.data import broad
from navlib.errors import InputError
from navlib.workbench.fit import load

FS = 285.7142857142857
G = 9.81
FIELD_NED = np.array([15.2, -0.3, 40.8])


def _trial(seconds=6.0, heading_rate_dps=20.0, tilt_deg=0.0, lost=(), seed=1):
    """A hand-turned IMU in BROAD's frames: body FLU, earth ENU, quaternion FLU -> ENU scalar first."""
    rng = np.random.default_rng(seed)
    n = int(seconds * FS)
    t = np.arange(n) / FS
    heading = np.mod(10.0 + heading_rate_dps * t, 360.0)  # clockwise from north (FRD/NED)
    roll = tilt_deg * np.sin(2 * np.pi * t / 3.0)
    # C_b^n (FRD -> NED) = Rz(heading) Ry(0) Rx(roll); BROAD's C_flu^enu = P C D
    C = Rotation.from_euler(
        "ZYX", np.column_stack([heading, np.zeros(n), roll]), degrees=True
    ).as_matrix()
    P = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]])
    D = np.diag([1.0, -1.0, -1.0])
    C_enu = P @ C @ D
    q_xyzw = Rotation.from_matrix(C_enu).as_quat()
    quat = np.column_stack([q_xyzw[:, 3], q_xyzw[:, :3]])
    mag_frd = np.einsum("nji,j->ni", C, FIELD_NED) + 0.01 * rng.standard_normal((n, 3))
    acc_frd = np.einsum("nji,j->ni", C, [0.0, 0.0, -G])
    for a, b in lost:  # optical reference lost
        quat[(t >= a) & (t < b)] = np.nan
    return (
        {
            "imu_gyr": np.zeros((n, 3)) + [0.0, 0.0, -np.radians(heading_rate_dps)],
            "imu_acc": acc_frd * [1, -1, -1],
            "imu_mag": mag_frd * [1, -1, -1],
            "opt_quat": quat,
            "opt_pos": np.tile([0.1, -0.5, 1.2], (n, 1)),
            "movement": (t > 1.0).astype(np.uint8)[:, None],
            "sampling_rate": np.array([[FS]]),
        },
        heading,
        C,
    )


def _write(folder, name, arrays):
    folder.mkdir(parents=True, exist_ok=True)
    savemat(folder / name, arrays)
    return folder / name


def test_rotation_helpers_agree_with_scipy():
    R = Rotation.random(50, random_state=3)
    q = np.column_stack([R.as_quat()[:, 3], R.as_quat()[:, :3]])
    assert np.allclose(broad.quat_to_matrix(q), R.as_matrix(), atol=1e-12)
    back = broad.matrix_to_quat(R.as_matrix())
    assert np.allclose(np.abs(np.sum(back * q, axis=1)), 1.0, atol=1e-12) and np.all(
        back[:, 0] >= 0
    )
    eul = broad.euler_zyx_deg(R.as_matrix())
    ref = R.as_euler("ZYX", degrees=True)  # heading, pitch, roll
    assert np.allclose(eul[:, 0], ref[:, 2]) and np.allclose(eul[:, 1], ref[:, 1])
    assert np.allclose(np.mod(eul[:, 2] - ref[:, 0] + 180, 360) - 180, 0, atol=1e-9)


def test_blocks_frames_and_attitude(tmp_path):
    arrays, heading, C = _trial(tilt_deg=20.0, lost=[(2.0, 2.3), (3.0, 3.02)])
    p = _write(tmp_path / "in", "05_undisturbed_slow_rotation_with_breaks_B.mat", arrays)
    blocks = broad.trial_blocks(broad.read_trial(p), 5)
    assert list(blocks.columns) == broad.COLUMNS_3D
    # 6 s of 0.1 s blocks, those lost for 0.3 s dropped; the block at 3.0 s keeps 80 % of its samples
    t = blocks["time_s"].to_numpy()
    assert not np.any((t > 2.0) & (t < 2.3)) and np.any((t > 3.0) & (t < 3.1))
    assert 55 <= len(blocks) <= 58
    C_mean = broad.quat_to_matrix(blocks[["q_w", "q_x", "q_y", "q_z"]].to_numpy())
    # the field rotated into NED with the written attitude is the Earth field; gravity points down
    field = np.einsum("nij,nj->ni", C_mean, blocks[["mag_x_ut", "mag_y_ut", "mag_z_ut"]].to_numpy())
    acc = np.einsum(
        "nij,nj->ni", C_mean, blocks[["acc_x_ms2", "acc_y_ms2", "acc_z_ms2"]].to_numpy()
    )
    slow = blocks["att_blur"].to_numpy() < 1e-4
    assert np.allclose(field[slow], FIELD_NED, atol=0.1)
    assert np.allclose(acc[slow], [0.0, 0.0, -G], atol=0.05)
    # heading clockwise from north, gyro in deg/s FRD (a right turn is +z down)
    i = np.argmin(np.abs(t - 4.0))
    assert abs((blocks["ref_heading_deg"][i] - (10.0 + 20.0 * t[i]) + 180) % 360 - 180) < 0.2
    assert np.allclose(blocks["gyr_z_dps"], 20.0)
    assert np.allclose(blocks[["pos_n_m", "pos_e_m", "pos_d_m"]].iloc[0], [-0.5, 0.1, -1.2])
    assert set(blocks["moving"]) == {0, 1} and (blocks["magnet_attached"] == 0).all()
    assert (blocks["att_blur"] >= 0).all()


def test_magnet_flags_from_the_stated_times():
    on, off = broad.MAGNET_TIMES[32]
    t = np.array([on - 3, on - 1, on + 2.9, on + 3.1, off - 2, off - 1, off + 1.4, off + 2])
    assert broad.magnet_flags(t, 32).tolist() == [0, -1, -1, 1, 1, -1, -1, 0]
    assert not broad.magnet_flags(t, 5).any()


def test_cli_writes_files_the_workbench_loads_and_never_overwrites(tmp_path, capsys):
    arrays, _, _ = _trial(seconds=40.0, heading_rate_dps=30.0, tilt_deg=3.0)
    src = tmp_path / "data_mat"
    _write(src, "05_undisturbed_slow_rotation_with_breaks_B.mat", arrays)
    _write(src, "28_disturbed_stationary_magnet_A.mat", arrays)
    out = tmp_path / "out"
    assert broad.main(["--in", str(src), "--out", str(out), "--trials", "05"]) == 0
    f3 = out / "3d" / "broad_05_undisturbed_slow_rotation_with_breaks_B.csv"
    level = out / "level" / "broad_trial05_level.csv"
    assert f3.is_file() and level.is_file()
    assert not (out / "3d" / "broad_28_stationary_magnet_A.csv").exists()
    sweep = load("compass", level)  # the level sweep is a compass file
    err = (sweep["measured_heading_deg"] - sweep["true_heading_deg"] + 180) % 360 - 180
    declination = np.degrees(np.arctan2(FIELD_NED[1], FIELD_NED[0]))
    assert np.allclose(err, -declination, atol=0.05)  # a perfect compass reads the magnetic heading
    frame = pd.read_csv(f3)
    assert frame["q_w"].min() >= 0 and frame["time_s"].is_monotonic_increasing
    before = f3.read_bytes()
    assert broad.main(["--in", str(src), "--out", str(out), "--trials", "05"]) == 2
    err_line = capsys.readouterr().err.strip()
    assert "already exists; not overwritten" in err_line and len(err_line.splitlines()) == 1
    assert f3.read_bytes() == before
    assert broad.main(["--in", str(src), "--out", str(tmp_path / "o2"), "--no-level"]) == 0
    assert (tmp_path / "o2" / "3d" / "broad_28_stationary_magnet_A.csv").is_file()
    assert not (tmp_path / "o2" / "level").exists()


@pytest.mark.parametrize(
    "change, message",
    [
        (lambda a: a.pop("imu_mag"), "no variable 'imu_mag'"),
        (
            lambda a: a.__setitem__("opt_quat", a["opt_quat"][:, :3]),
            "variable 'opt_quat' has shape",
        ),
        (lambda a: a.__setitem__("imu_acc", a["imu_acc"][:-5]), "variable 'imu_acc' has"),
        (
            lambda a: a.__setitem__("sampling_rate", np.array([[0.0]])),
            "'sampling_rate' must be one positive",
        ),
        (lambda a: a.pop("sampling_rate"), "no variable 'sampling_rate'"),
    ],
)
def test_bad_trial_files_one_line(tmp_path, change, message):
    arrays, _, _ = _trial(seconds=2.0)
    change(arrays)
    p = _write(tmp_path, "05_x.mat", arrays)
    with pytest.raises(InputError, match=message) as err:
        broad.read_trial(p)
    assert "\n" not in str(err.value) and "05_x.mat" in str(err.value)


def test_bad_folders_and_names(tmp_path, capsys):
    with pytest.raises(InputError, match="no such folder"):
        broad.convert(tmp_path / "nothing", tmp_path / "out")
    (tmp_path / "empty").mkdir()
    with pytest.raises(InputError, match="no BROAD trial file"):
        broad.convert(tmp_path / "empty", tmp_path / "out")
    (tmp_path / "bad").mkdir()
    (tmp_path / "bad" / "07_not_matlab.mat").write_text("hello")
    with pytest.raises(InputError, match="07_not_matlab.mat: not a readable MATLAB file"):
        broad.convert(tmp_path / "bad", tmp_path / "out")
    with pytest.raises(InputError, match="no file for trial 09"):
        broad.convert(tmp_path / "bad", tmp_path / "out", trials=[9])
    assert (
        broad.main(["--in", str(tmp_path / "bad"), "--out", str(tmp_path / "o"), "--trials", "x"])
        == 2
    )
    assert "--trials" in capsys.readouterr().err
    with pytest.raises(InputError, match="not a BROAD trial file name"):
        broad.output_name("trial.mat")
    assert (
        broad.output_name("32_disturbed_attached_magnet_1cm.mat")
        == "broad_32_attached_magnet_1cm.csv"
    )
