"""Scenes from numpy arrays and from / to files; errors carry the CLI's messages."""

import subprocess

import numpy as np
import pytest

import strata
from conftest import DATA, SLICES


def square(size, n_per_side=4):
    t = np.linspace(0.0, 1.0, n_per_side, endpoint=False)
    s = size
    sides = [
        np.c_[-s + 2 * s * t, np.full_like(t, -s)],
        np.c_[np.full_like(t, s), -s + 2 * s * t],
        np.c_[s - 2 * s * t, np.full_like(t, s)],
        np.c_[np.full_like(t, -s), s - 2 * s * t],
    ]
    return np.vstack(sides)


def test_scene_from_arrays_keeps_parameters():
    scene = strata.scene_from_arrays(
        [square(1.0), square(2.0)],
        names=["body", "shirt"],
        closed=True,
        thickness=[0.01, 0.02],
        weight=[4.0, 1.0],
        units="m",
    )
    assert len(scene) == 2 and scene.names == ["body", "shirt"] and scene.units == "m"
    assert scene["shirt"].thickness == 0.02 and scene[0].weight == 4.0 and scene[0].closed
    assert scene.is_implicit_stack and scene.relation(0, 1) == "under"
    assert scene.required_separation(0, 1) == pytest.approx(0.015)
    np.testing.assert_array_equal(scene[1].points, square(2.0))
    assert scene[0].points.dtype == np.float64 and scene[0].points.shape == (16, 2)


def test_outer_links_make_side_by_side_layers():
    legs = [square(0.5) + [-1.0, 0.0], square(0.5) + [1.0, 0.0]]
    skirt = square(3.0)
    scene = strata.scene_from_arrays(
        legs + [skirt],
        names=["left", "right", "skirt"],
        closed=True,
        outer=[["skirt"], ["skirt"], []],
    )
    assert not scene.is_implicit_stack
    assert scene.relation(0, 1) == "side-by-side" and scene.relation(1, 2) == "under"


@pytest.mark.parametrize("ext", ["json", "svg"])
def test_file_round_trip_is_exact(tmp_path, ext):
    scene = strata.read_scene(SLICES / "mh_casualsuit03_y+1.50.json")
    path = tmp_path / f"scene.{ext}"
    strata.write_scene(scene, path)
    again = strata.read_scene(path)
    assert again.names == scene.names
    for a, b in zip(scene.layers, again.layers):
        np.testing.assert_array_equal(a.points, b.points)
        assert (a.closed, a.thickness, a.weight, a.outer) == (b.closed, b.thickness, b.weight, b.outer)
    # and the written file is complete: no temporary file left beside it
    assert sorted(p.name for p in tmp_path.iterdir()) == [f"scene.{ext}"]


def test_arrays_round_trip_through_json(tmp_path):
    rng = np.random.default_rng(3)
    pts = np.cumsum(rng.normal(size=(50, 2)), axis=0)
    scene = strata.scene_from_arrays([pts], names=["walk"], thickness=0.1)
    strata.write_scene(scene, tmp_path / "walk.json")
    np.testing.assert_array_equal(strata.read_scene(tmp_path / "walk.json")["walk"].points, pts)


def cli_error(cli, *args):
    run = subprocess.run([cli, *map(str, args)], capture_output=True, text=True)
    assert run.returncode == 2, run.stderr
    line = run.stderr.strip().splitlines()[-1]
    assert line.startswith("strata: error: ")
    return line[len("strata: error: "):]


@pytest.mark.parametrize("name", ["negative_thickness.json", "syntax_error.json"])
def test_bad_files_raise_the_cli_message(cli, name, tmp_path):
    path = DATA / "bad" / name
    with pytest.raises(strata.InvalidInput) as e:
        strata.read_scene(path)
    assert str(path) in str(e.value)
    assert str(e.value) == cli_error(cli, "check", path)


def test_missing_file_is_an_io_error_naming_it(tmp_path):
    path = tmp_path / "nowhere.json"
    with pytest.raises(strata.IoError) as e:
        strata.read_scene(path)
    assert isinstance(e.value, OSError) and "nowhere.json" in str(e.value)


def test_unknown_extension_is_refused(tmp_path):
    with pytest.raises(strata.InvalidInput, match="scene.txt"):
        strata.write_scene(strata.read_scene(SLICES / "mh_casualsuit03_y+1.50.json"), tmp_path / "scene.txt")


def test_invalid_arrays_name_layer_and_point():
    bad = square(1.0)
    bad[3, 1] = np.nan
    with pytest.raises(strata.InvalidInput, match=r"layer 'x'.*point 3"):
        strata.scene_from_arrays([bad], names=["x"], closed=True)
    with pytest.raises(strata.InvalidInput, match=r"\(n, 2\)"):
        strata.Layer(np.zeros((4, 3)), name="y")
    with pytest.raises(strata.InvalidInput, match="thickness"):
        strata.scene_from_arrays([square(1.0)], thickness=-1.0)
    with pytest.raises(strata.InvalidInput, match="name already used"):
        strata.scene_from_arrays([square(1.0), square(2.0)], names=["a", "a"])
