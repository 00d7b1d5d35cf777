"""The exchange package's building blocks: number tables, rotations, all-or-nothing writes, the command line."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from liganimate.runtime.exchange import write_files
from liganimate.runtime.exchange._numbers import format_rows
from liganimate.runtime.exchange._rotations import (
    continuous_quaternions,
    decompose_trs,
    euler_zyx_from_matrix,
    matrix_from_axes,
    matrix_from_euler_zyx,
    quaternion_from_matrix,
)


def _parse(data: bytes, columns: int) -> np.ndarray:
    return np.array(data.split(), dtype=np.float64).reshape(-1, columns)


@pytest.mark.parametrize("decimals", [0, 3, 8])
def test_format_rows_writes_each_number_rounded(decimals):
    rng = np.random.default_rng(1)
    v = rng.normal(size=(200, 5)) * np.array([1e-3, 1.0, 180.0, 1e4, 1e8])
    v[0, 0] = -0.0
    v[1, 1] = -1e-12  # rounds to zero: written without a sign
    text = format_rows(v, decimals)
    assert text.count(b"\n") == 200
    back = _parse(text, 5)
    np.testing.assert_allclose(back, np.round(v, decimals), rtol=0, atol=10.0**-decimals * 0.5 + 1e-6)
    assert b"-0 " not in text and b"-0." + b"0" * decimals + b" " not in text
    expected = "\n".join(" ".join(f"{x:.{decimals}f}" for x in row) for row in v.tolist())
    expected = expected.replace("-0." + "0" * decimals, "0." + "0" * decimals) if decimals else expected
    assert text.split() == [t.encode() if t != "-0" else b"0" for t in expected.split()]


def test_format_rows_prefixes_and_huge_numbers():
    text = format_rows(
        np.array([[3.0, -2.5], [12.0, 1e20]]), [0, 2], columns_prefix=["FRAME ", " POSITION "], suffix=";\n"
    )
    lines = text.decode().splitlines()
    assert lines[0].split() == ["FRAME", "3", "POSITION", "-2.50;"]
    assert lines[1].split() == ["FRAME", "12", "POSITION", "100000000000000000000.00;"]
    with pytest.raises(ValueError):
        format_rows(np.array([[np.nan]]), 2)


def test_euler_zyx_round_trips_and_matches_scipy():
    rng = np.random.default_rng(2)
    angles = rng.uniform([-180, -90, -180], [180, 90, 180], size=(500, 3))
    R = matrix_from_euler_zyx(angles)
    np.testing.assert_allclose(R, Rotation.from_euler("ZYX", angles[:, ::-1], degrees=True).as_matrix(), atol=1e-12)
    np.testing.assert_allclose(euler_zyx_from_matrix(R), angles, atol=1e-9)


@pytest.mark.parametrize("ay", [90.0, -90.0])
def test_euler_zyx_at_gimbal_lock_gives_the_same_rotation(ay):
    R = matrix_from_euler_zyx(np.array([[30.0, ay, -50.0]]))
    back = euler_zyx_from_matrix(R)
    assert back[0, 2] == 0.0
    np.testing.assert_allclose(matrix_from_euler_zyx(back), R, atol=1e-12)


@pytest.mark.parametrize("order", ["ZXY", "XYZ", "YXZ", "YZX", "XZY", "ZY", "X"])
def test_matrix_from_axes_is_intrinsic_in_listed_order(order):
    rng = np.random.default_rng(3)
    a = rng.uniform(-170, 170, size=(50, len(order)))
    want = Rotation.from_euler(order, a, degrees=True).as_matrix()
    np.testing.assert_allclose(matrix_from_axes(order, a), want, atol=1e-12)


def test_quaternions_match_scipy_and_stay_continuous():
    rng = np.random.default_rng(4)
    R = Rotation.random(300, random_state=5).as_matrix()
    q = quaternion_from_matrix(R)
    ref = Rotation.from_matrix(R).as_quat()
    sign = np.sign(np.sum(q * ref, axis=1))
    np.testing.assert_allclose(q, ref * sign[:, None], atol=1e-12)
    # Half turns (trace -1) take the other branches.
    half = Rotation.from_rotvec(np.pi * rng.normal(size=(20, 3)) / np.linalg.norm(rng.normal(size=(20, 3)))).as_matrix()
    np.testing.assert_allclose(Rotation.from_quat(quaternion_from_matrix(half)).as_matrix(), half, atol=1e-12)
    path = quaternion_from_matrix(Rotation.from_rotvec(np.linspace(0, 6, 50)[:, None] * [0, 0, 1]).as_matrix())
    smooth = continuous_quaternions(path)
    assert (np.sum(smooth[1:] * smooth[:-1], axis=1) > 0).all()
    assert (np.sum(path[1:] * path[:-1], axis=1) < 0).any()  # the test has something to fix


def test_decompose_trs_rebuilds_or_reports_a_shear():
    R = Rotation.from_euler("y", 30, degrees=True).as_matrix()
    M = np.eye(4)
    M[:3, :3] = R @ np.diag([1.0, 2.0, -0.5])
    M[:3, 3] = [1, 2, 3]
    t, Rr, s, ok = decompose_trs(M)
    assert ok and np.linalg.det(Rr) > 0
    np.testing.assert_allclose(Rr @ np.diag(s), M[:3, :3], atol=1e-12)
    np.testing.assert_allclose(t, [1, 2, 3])
    M[:3, :3] = np.diag([1.0, 2.0, 1.0]) @ Rotation.from_euler("z", 30, degrees=True).as_matrix()
    assert not decompose_trs(M)[3]


def test_write_files_is_all_or_nothing(tmp_path):
    keep = tmp_path / "a.txt"
    keep.write_bytes(b"old")
    with pytest.raises(OSError):
        write_files([(str(keep), b"new"), (str(tmp_path / "missing" / "b.txt"), b"x")])
    assert keep.read_bytes() == b"old"
    assert sorted(os.listdir(tmp_path)) == ["a.txt"]
    write_files([(str(keep), b"new"), (str(tmp_path / "b.txt"), b"x")])
    assert keep.read_bytes() == b"new" and (tmp_path / "b.txt").read_bytes() == b"x"


def _cli(*args, cwd=None):
    return subprocess.run(
        [sys.executable, "-m", "liganimate", *args], check=False, capture_output=True, text=True, cwd=cwd
    )


def test_export_needs_a_known_extension(tmp_path):
    src = tmp_path / "a.lig"
    src.write_text("      X = 1\n")
    r = _cli("export", str(src), "-o", str(tmp_path / "a.obj"))
    assert r.returncode == 1 and ".glb, .gltf, .bvh, .urdf, .csv or .json" in r.stderr
    assert sorted(os.listdir(tmp_path)) == ["a.lig"]


def test_export_of_a_program_without_scenes_says_so(tmp_path):
    src = tmp_path / "a.lig"
    src.write_text("      X = 1\n")
    r = _cli("export", str(src), "-o", str(tmp_path / "a.glb"))
    assert r.returncode == 1 and "shoots no scene" in r.stderr and "Traceback" not in r.stderr


def test_export_reports_program_errors_as_diagnostics(tmp_path):
    src = tmp_path / "a.lig"
    src.write_text("      X = 1 / 0\n")
    r = _cli("export", str(src), "-o", str(tmp_path / "a.glb"))
    assert r.returncode == 1 and f"{src}:1:" in r.stderr and "division by zero" in r.stderr
    assert sorted(os.listdir(tmp_path)) == ["a.lig"]


def test_import_names_come_from_the_file_and_can_be_chosen(tmp_path):
    from test_exchange_bvh import BAD_BASE

    (tmp_path / "my-walk.bvh").write_text(BAD_BASE)
    r = _cli("import", "my-walk.bvh", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    text = (tmp_path / "my-walk.lig").read_text()
    assert "MODEL MY_WALK_FIGURE" in text and "STARTMOTION MY_WALK" in text
    r = _cli("import", "my-walk.bvh", "-o", "x.lig", "--model", "same", "--motion", "SAME", cwd=tmp_path)
    assert r.returncode == 1 and "cannot both be called SAME" in r.stderr
    r = _cli("import", "my-walk.bvh", "-o", "x.lig", "--model", "2bad", cwd=tmp_path)
    assert r.returncode == 2 and "not a LIG name" in r.stderr
    assert not (tmp_path / "x.lig").exists()
