"""simplify / untangle / check / slice / sample_field on real slices and generated scenes:
geometric invariants, budgets, the CLI's outputs and messages, the GIL released."""

import subprocess
import threading
import time

import numpy as np
import pytest

import strata
from conftest import DATA, SLICES


def folded_stack(layers=5, points=3000, spacing=0.04):
    """The demo's folded curve offset along its normal: stacked open layers that come close."""
    x = np.linspace(0.0, 10.0, points)
    y = 0.5 * np.sin(0.6 * x) + 0.18 * np.sin(2.3 * x + 0.5) + 0.07 * np.sin(6.1 * x)
    dy = np.gradient(y, x)
    normal = np.c_[-dy, np.ones_like(dy)] / np.sqrt(1 + dy**2)[:, None]
    arrays = [np.c_[x, y] + k * spacing * normal for k in range(layers)]
    return strata.scene_from_arrays(arrays, thickness=0.01)


@pytest.mark.parametrize("path", sorted(SLICES.glob("*.json")), ids=lambda p: p.name)
def test_simplify_keeps_slices_collision_free_within_budget(path):
    scene = strata.read_scene(path)
    result, report = strata.simplify(scene, remove=0.9)
    assert report.collision_free
    # an independent exact check of the output, against its input as the CLI's check does
    checked = strata.check(result, scene)
    assert checked.collision_free and checked.crossings == 0 and checked.nesting_violations == 0
    assert sum(checked.self_crossings) == 0
    assert result.names == scene.names and len(report.layers) == len(scene)
    for before, after, layer in zip(scene.layers, result.layers, report.layers):
        assert layer.before == len(before) and layer.after == len(after)
        target = max(len(before) - int(0.9 * len(before)), 3 if before.closed else 2)
        assert layer.after <= layer.before
        assert layer.after >= layer.target
        # a layer misses its target only by the removals it refused, or by the vertices the
        # last resort put back
        assert layer.after - layer.target <= layer.refused + report.restored
        if not before.closed and report.trimmed_ends == 0:  # open layers keep their ends
            np.testing.assert_array_equal(after.points[[0, -1]], before.points[[0, -1]])
        # the reported Hausdorff distance is the one the checker measures
        assert checked.hausdorff[layer.name] == pytest.approx(layer.hausdorff, rel=1e-6, abs=1e-9)
        assert target >= 0
    assert report.seconds_total > 0
    assert report.to_dict()["collision_free"] is True
    assert report.to_dict()["restored"] == report.restored
    assert report.to_dict()["rolled_vertices"] == report.rolled_vertices


def test_naive_decimation_crosses_where_strata_does_not():
    scene = folded_stack(points=600)
    naive, naive_report = strata.simplify(scene, remove=0.9, decimator="random", untangle=False)
    result, report = strata.simplify(scene, remove=0.9, decimator="random")
    assert strata.check(naive).crossings > 0 and naive_report.crossings > 0
    assert report.collision_free and strata.check(result).crossings == 0
    assert all(l.after == l.target + 0 or l.refused > 0 for l in report.layers)


def test_keep_sets_the_vertex_budget():
    scene = strata.read_scene(SLICES / "cipc_multilayer_y+0.00.json")
    result, report = strata.simplify(scene, keep=12)
    for layer, out in zip(report.layers, result.layers):
        assert layer.target == min(12, layer.before)
        assert len(out) >= layer.target


def test_same_output_as_the_cli(cli, tmp_path):
    path = SLICES / "mh_casualsuit05_y+4.00.json"
    subprocess.run([cli, "simplify", str(path), "-o", str(tmp_path / "cli.json"), "--remove", "0.8",
                    "--decimator", "random", "--seed", "7"], check=True, capture_output=True)
    result, _ = strata.simplify(strata.read_scene(path), remove=0.8, decimator="random", seed=7)
    strata.write_scene(result, tmp_path / "py.json")
    assert (tmp_path / "py.json").read_bytes() == (tmp_path / "cli.json").read_bytes()


def test_trim_ends_as_the_cli(cli, tmp_path):
    # A lapel bent around another piece's end: with its ends kept it stays above its target.
    path = SLICES / "mh_casualsuit05_y+4.00.json"
    scene = strata.read_scene(path)
    kept, with_ends = strata.simplify(scene, remove=0.9, trim_ends=False)
    trimmed, report = strata.simplify(scene, remove=0.9)
    assert with_ends.trimmed_ends == 0 and not with_ends.targets_met
    assert report.trimmed_ends >= 1 and report.targets_met and report.collision_free
    subprocess.run([cli, "simplify", str(path), "-o", str(tmp_path / "cli.json"), "--remove", "0.9",
                    "--no-trim-ends"], check=True, capture_output=True)
    strata.write_scene(kept, tmp_path / "py.json")
    assert (tmp_path / "py.json").read_bytes() == (tmp_path / "cli.json").read_bytes()


@pytest.mark.parametrize(
    "kwargs, args",
    [
        (dict(remove=1.5), ["--remove", "1.5"]),
        (dict(keep_gaps=2.0), ["--keep-gaps", "2"]),
        (dict(decimator="nope"), ["--decimator", "nope"]),
    ],
)
def test_bad_parameters_raise_the_cli_message(cli, tmp_path, kwargs, args):
    path = SLICES / "mh_elegantsuit01_y+0.50.json"
    run = subprocess.run([cli, "simplify", str(path), "-o", str(tmp_path / "x.json"), *args],
                         capture_output=True, text=True)
    assert run.returncode == 2
    message = run.stderr.strip().splitlines()[-1].removeprefix("strata: error: ")
    with pytest.raises(strata.InvalidInput) as e:
        strata.simplify(strata.read_scene(path), **kwargs)
    assert str(e.value) == message


def test_crossing_input_is_untangled_first_or_refused():
    scene = strata.read_scene(DATA / "crossing_pair.json")
    assert strata.check(scene).crossings > 0
    result, report = strata.simplify(scene, remove=0.5)
    assert report.collision_free and strata.check(result).crossings == 0
    with pytest.raises(strata.InvalidInput, match="not collision-free.*first: layer 'inner'"):
        strata.simplify(scene, input_crossings="fail")


def test_untangle_mends_a_crossing_pair():
    scene = strata.read_scene(DATA / "crossing_pair.json")
    before = strata.check(scene)
    assert not before.collision_free and "crossings" in before.summary
    result, report = strata.untangle(scene)
    assert report.collision_free and report.crossings_before == before.crossings
    assert strata.check(result).collision_free
    assert strata.check(scene).crossings == before.crossings  # the input is not changed


def test_untangle_gives_up_when_stalled_only_when_asked():
    # A folded stack at 95% that no try cleans (13 s of 25 tries by default): asked to, every
    # try gives up early, and the report says so.
    scene = strata.read_scene(DATA / "folded_stack_tangled_95.json")
    result, report = strata.untangle(scene, give_up_when_stalled=True)
    assert not report.collision_free and report.gave_up
    assert report.passes < report.tries * 64  # the tries ended before their pass cap
    assert not strata.check(result).collision_free


def test_untangle_keeps_a_roll_unless_told_the_global_order():
    # A shirt rolled over the end of a jacket, tangled by naive random decimation (as the CLI
    # tests do): by default its rolled regions keep their inferred sides; the global order
    # alone pulls the roll back under the jacket: clean by the global order, not by the
    # original's sides.
    original = strata.read_scene(DATA / "rolled_shirt_over_jacket.json")
    tangled, _ = strata.simplify(original, remove=0.95, decimator="random", seed=1, untangle=False)
    assert strata.check(tangled).crossings > 0
    kept, report = strata.untangle(tangled)
    assert report.collision_free and report.inferred_sides
    # Judged against the original's sides, as `strata check --reference` does: the roll kept.
    assert strata.check(kept, reference=original).collision_free
    unrolled, global_report = strata.untangle(tangled, global_order=True)
    assert not global_report.inferred_sides
    assert not strata.check(unrolled, reference=original).collision_free


def test_check_lists_crossings():
    scene = strata.read_scene(DATA / "crossing_pair.json")
    r = strata.check(scene)
    assert r.crossings == len(r.crossing_list) > 0
    a, seg_a, b, seg_b, (x, y), touch = r.crossing_list[0]
    assert (a, b) == ("inner", "outer") and 0 <= x <= 4 and abs(y) < 1e-12


def cube(center, half):
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)
    faces = np.array([[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4],
                      [1, 5, 7, 3]])
    return np.asarray(center) + half * corners, faces


def test_slice_meshes_from_arrays_nests_the_layers():
    body = ("body",) + cube([0, 0, 0], 1.0)
    coat = ("coat",) + cube([0, 0, 0], 1.5)
    scenes = strata.slice([coat, body], at=[0.25, 5.0], axis="y", order=["body", "coat"],
                          thickness=0.01)
    assert scenes[1] is None  # the plane misses both meshes
    scene = scenes[0]
    assert scene.names == ["body_1", "coat_1"]
    assert scene.relation(0, 1) == "under" and all(l.closed for l in scene.layers)
    xy = scene["coat_1"].points
    np.testing.assert_allclose(np.abs(xy).max(axis=0), [1.5, 1.5])
    assert strata.check(scene).collision_free


def test_slice_reports_bad_faces_and_missing_files(tmp_path):
    v, f = cube([0, 0, 0], 1.0)
    f = f.copy()
    f[2, 1] = 99
    with pytest.raises(strata.InvalidInput, match="face 2 has vertex index 99"):
        strata.slice([("body", v, f)], at=0.0)
    with pytest.raises(strata.IoError, match="nowhere.obj"):
        strata.slice([tmp_path / "nowhere.obj"], at=0.0)


def test_slice_reads_a_mesh_file(tmp_path):
    v, f = cube([0, 0, 0], 1.0)
    lines = [f"v {x} {y} {z}" for x, y, z in v] + ["f " + " ".join(str(i + 1) for i in face) for face in f]
    (tmp_path / "box.obj").write_text("\n".join(lines) + "\n")
    [scene] = strata.slice([tmp_path / "box.obj"], at=0.5, axis="z")
    assert scene.names == ["box_1"] and len(scene["box_1"]) >= 4


@pytest.mark.parametrize("backend", ["indexed", "grid"])
def test_sample_field_of_a_circle_is_its_distance(backend):
    t = np.linspace(0, 2 * np.pi, 400, endpoint=False)
    circle = np.c_[np.cos(t), np.sin(t)]
    scene = strata.scene_from_arrays([circle], names=["c"], closed=True, thickness=0.02)
    g = strata.sample_field(scene, "c", spacing=0.01, bounds=(-1.1, -1.1, 1.1, 1.1),
                            backend=backend, band_width=0.2)
    assert g.value.shape == (220, 220) and g.in_band.dtype == bool
    xs = -1.1 + (np.arange(220) + 0.5) * 0.01
    ys = 1.1 - (np.arange(220) + 0.5) * 0.01
    X, Y = np.meshgrid(xs, ys)
    exact = np.hypot(X, Y) - 1.0  # negative inside, positive outside
    band = np.abs(exact) < 0.15
    # the polygon is within 1 - cos(pi / 400) of the circle; the grid adds its interpolation
    tol = 1e-4 if backend == "indexed" else 0.01
    np.testing.assert_allclose(g.value[band], exact[band], atol=tol)
    assert g.in_band[band].all()
    grad = np.hypot(g.gradient_x[band], g.gradient_y[band])
    np.testing.assert_allclose(grad, 1.0, atol=0.05)


def test_simplify_releases_the_gil():
    scene = folded_stack(points=20000)
    ticks = [0]
    stop = threading.Event()

    def tick():
        while not stop.is_set():
            ticks[0] += 1
            time.sleep(0.001)

    thread = threading.Thread(target=tick)
    thread.start()
    time.sleep(0.05)
    start_ticks = ticks[0]
    start = time.perf_counter()
    _, report = strata.simplify(scene, remove=0.9)
    elapsed = time.perf_counter() - start
    during = ticks[0] - start_ticks
    stop.set()
    thread.join()
    assert elapsed > 0.1, "the scene is too small to tell"
    # with the GIL held the other thread could not tick during the call (at most once at its
    # edges); released, it ticks about every millisecond (fewer on a loaded machine)
    assert during >= 10, (during, elapsed)


def test_counts_must_be_whole_numbers():
    scene = strata.read_scene(SLICES / "mh_elegantsuit01_y+0.50.json")
    with pytest.raises(strata.InvalidInput, match=r"keep must be a whole number >= 0 \(got -1\)"):
        strata.simplify(scene, keep=-1)
    with pytest.raises(strata.InvalidInput, match=r"untangle_batch must be a whole number >= 1"):
        strata.simplify(scene, untangle_batch=0)
    with pytest.raises(strata.InvalidInput, match="layer 'named'"):
        strata.Layer(np.zeros((3, 3)), name="named")


def test_progress_reports_and_cancels():
    scene = folded_stack(points=2000)
    seen = []
    strata.simplify(scene, progress=lambda stage, f: seen.append((stage, f)) or True)
    assert seen and seen[0][0] == "simplify" and all(0 <= f <= 1 for _, f in seen)
    assert [f for _, f in seen] == sorted(f for _, f in seen)
    with pytest.raises(strata.Cancelled):
        strata.simplify(scene, progress=lambda stage, f: f < 0.3)

    def boom(stage, f):
        raise KeyError("from the callback")

    with pytest.raises(KeyError, match="from the callback"):
        strata.simplify(scene, progress=boom)


def test_progress_cancels_the_untangling_of_a_crossing_input():
    # This folded stack takes 29 tries to untangle (about a minute): the callback stops it in
    # its first rounds, while the input is untangled, before any removal.
    scene = strata.read_scene(str(DATA / "folded_stack_tangled_95.json"))
    seen = []

    def first_rounds(stage, f):
        seen.append(stage)
        return len(seen) < 3

    with pytest.raises(strata.Cancelled):
        strata.simplify(scene, progress=first_rounds)
    assert seen[0].startswith("untangle") and "simplify" not in seen
    with pytest.raises(strata.InvalidInput, match="time_limit is for strata.batch"):
        strata._strata._simplify(scene, dict(time_limit=1.0), None)


GARMENTS = DATA.parents[2] / "shared" / "data" / "garments" / "makehuman"


@pytest.mark.skipif(not GARMENTS.is_dir(), reason="no ../shared/data/garments beside the project")
def test_slice_of_a_real_outfit_matches_the_cli(cli, tmp_path):
    body, suit = GARMENTS / "male_generic.obj", GARMENTS / "male_casualsuit03.obj"
    subprocess.run([cli, "slice", f"body={body}", f"suit={suit}", "--order", "body,suit",
                    "--units", "dm", "--at", "1.5", "-o", str(tmp_path / "cli.json")],
                   check=True, capture_output=True)
    [scene] = strata.slice([("body", body), ("suit", suit)], at=1.5, order=["body", "suit"],
                           units="dm")
    strata.write_scene(scene, tmp_path / "py.json")
    assert (tmp_path / "py.json").read_bytes() == (tmp_path / "cli.json").read_bytes()
    assert any(n.startswith("body_") for n in scene.names)
    assert any(n.startswith("suit_") for n in scene.names)
