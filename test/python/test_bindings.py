"""rbsim's Python package against the C++ outputs: `rbsim run`'s files, its CSVs bit for bit, its
recordings and `rbsim check`. Run by CTest (python.bindings) with the built package on PYTHONPATH
and RBSIM_EXE naming the `rbsim` command; every comparison is exact (no tolerance)."""
import gc
import os
import re
import subprocess
import threading
from pathlib import Path

import numpy as np
import pytest

import rbsim

SOURCE = Path(os.environ["RBSIM_SOURCE"])
EXE = os.environ["RBSIM_EXE"]
SCENES = sorted((SOURCE / "scenes").glob("*.xml")) + [
    SOURCE / "test/data/fosssim/scenes/windtests/test00ee.xml",
    SOURCE / "test/data/fosssim/scenes/hollistictests/airplane.xml",
]
CANTILEVER = SOURCE / "scenes/cantilever.xml"
COLUMNS = ["x", "y", "theta", "vx", "vy", "omega"]


def cli(*args):
    p = subprocess.run([EXE, *map(str, args)], capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    return p


def read_csv(path):
    lines = Path(path).read_text().splitlines()
    header = lines[0].split(",")
    return [dict(zip(header, (float(v) for v in line.split(",")))) for line in lines[1:]]


# --- rbsim.run = rbsim run, byte for byte ---------------------------------------------------------

def test_run_writes_what_the_command_writes(tmp_path):
    outputs = ["csv", "energy_csv", "fosssim_out", "record"]
    names = {"csv": "b.csv", "energy_csv": "e.csv", "fosssim_out": "f.bin", "record": "r.mcap"}
    commands = tmp_path / "steer.yaml"
    commands.write_text("- {step: 40, set: {forces.0.fy: -3.5}}\n- {t: 0.15, impulse: {body: 1, j: [0, 4], p: [0, 0]}}\n")
    (tmp_path / "py").mkdir()
    (tmp_path / "cli").mkdir()
    done = rbsim.run(CANTILEVER, steps=300, commands=commands,
                     **{k: tmp_path / "py" / names[k] for k in outputs})
    assert done == 300
    cli("run", CANTILEVER, "--steps", 300, "--commands", commands, "-q",
        *sum((["--" + k.replace("_", "-"), tmp_path / "cli" / names[k]] for k in outputs), []))
    for k in outputs:
        assert (tmp_path / "py" / names[k]).read_bytes() == (tmp_path / "cli" / names[k]).read_bytes(), k


def test_run_writes_a_bag_directory_as_the_command_does(tmp_path):
    rbsim.run(str(CANTILEVER), duration=0.5, record=tmp_path / "py_bag", compression="lz4", record_every=3,
              topics=["body_states", "energy"])
    cli("run", CANTILEVER, "--duration", 0.5, "--record", tmp_path / "cli_bag", "--compression", "lz4",
        "--record-every", 3, "--topics", "body_states,energy", "-q")
    assert (tmp_path / "py_bag/py_bag_0.mcap").read_bytes() == (tmp_path / "cli_bag/cli_bag_0.mcap").read_bytes()
    py_meta = (tmp_path / "py_bag/metadata.yaml").read_text().replace("py_bag", "BAG")
    assert py_meta == (tmp_path / "cli_bag/metadata.yaml").read_text().replace("cli_bag", "BAG")


def test_run_refuses_what_the_command_refuses(tmp_path):
    out = tmp_path / "r.mcap"
    out.write_bytes(b"mine")
    with pytest.raises(rbsim.Error, match=r"exists \(use overwrite=True to replace it\)"):
        rbsim.run(CANTILEVER, steps=5, record=out)
    assert out.read_bytes() == b"mine"
    assert rbsim.run(CANTILEVER, steps=5, record=out, overwrite=True) == 5
    with pytest.raises(ValueError, match="compression"):
        rbsim.run(CANTILEVER, steps=5, record=tmp_path / "x.mcap", compression="brotli")
    with pytest.raises(ValueError, match="namespace"):
        rbsim.run(CANTILEVER, steps=5, record=tmp_path / "x.mcap", namespace="a//b")
    bad = tmp_path / "bad.yaml"
    bad.write_text("- {step: 1, impulse: {body: 99, j: [0, 1], p: [0, 0]}}\n")
    with pytest.raises(rbsim.Error, match=r"bad.yaml:1: impulse.body"):
        rbsim.run(CANTILEVER, steps=5, commands=bad)
    assert not (tmp_path / "x.mcap").exists()


# --- stepping from Python = rbsim run --csv, bit for bit -----------------------------------------

@pytest.mark.parametrize("scene", SCENES, ids=lambda p: p.stem)
def test_stepping_equals_the_csv_bit_for_bit(tmp_path, scene):
    steps = 150
    cli("run", scene, "--steps", steps, "--csv", tmp_path / "b.csv", "--energy-csv", tmp_path / "e.csv", "-q")
    bodies, energy = read_csv(tmp_path / "b.csv"), read_csv(tmp_path / "e.csv")
    world = rbsim.load_scene(scene).world()
    n = world.body_count
    for k in range(steps + 1):
        if k:
            world.step()
        rows = bodies[k * n:(k + 1) * n]
        for c in COLUMNS:
            assert np.array_equal(getattr(world, c), [r[c] for r in rows]), (k, c)
        e = {**world.energy(), **world.totals()}
        assert all(e[c] == energy[k][c] for c in e), (k, e, energy[k])
        assert world.step_index == k and world.t == energy[k]["t"]


def test_step_until_takes_the_steps_a_duration_takes(tmp_path):
    cli("run", CANTILEVER, "--duration", 0.07, "--energy-csv", tmp_path / "e.csv", "-q")
    last = read_csv(tmp_path / "e.csv")[-1]
    world = rbsim.load_scene(CANTILEVER).world()
    world.step_until(0.07)
    assert world.step_index == last["step"] and world.energy()["E"] == last["E"]
    world.step_until(0.01)  # already past: no step back
    assert world.step_index == last["step"]


# --- the views are the World's memory ---------------------------------------------------------------

def test_views_are_views_of_the_world():
    world = rbsim.load_scene(CANTILEVER).world()
    x = world.x
    before = x.copy()
    address = x.__array_interface__["data"][0]
    world.step(10)
    assert not np.array_equal(x, before), "a step changes the array handed out earlier"
    assert world.x.__array_interface__["data"][0] == address, "the same memory every time"
    assert np.array_equal(x, world.x) and np.shares_memory(x, world.x)
    assert x.dtype == np.float64 and x.flags.c_contiguous and x.flags.writeable
    assert not world.mass.flags.writeable and world.mass.shape == (world.body_count,)


def test_written_state_is_where_the_next_step_starts():
    scene = rbsim.load_scene(CANTILEVER)
    a, b = scene.world(), scene.world()
    a.step(37)
    for c in COLUMNS:  # b, still at step 0, takes a's state through the views
        getattr(b, c)[:] = getattr(a, c)
    a.step(25)
    b.step(25)
    for c in COLUMNS:
        assert np.array_equal(getattr(a, c), getattr(b, c)), c
    c = scene.world()
    c.theta = a.theta  # whole-array assignment copies into the World's memory
    assert np.array_equal(c.theta, a.theta)


def test_bad_assignments_are_refused():
    world = rbsim.load_scene(CANTILEVER).world()
    n = world.body_count
    with pytest.raises(ValueError, match=r"expected shape \(%d,\)" % n):
        world.x = np.zeros(n + 1)
    with pytest.raises(ValueError, match="expected shape"):
        world.vx = np.zeros((n, 1))
    with pytest.raises(ValueError):
        world.y = ["a"] * n
    with pytest.raises(AttributeError):
        world.mass = np.ones(n)
    with pytest.raises(ValueError, match="read-only"):
        world.mass[0] = 1.0
    world.omega = list(range(n))  # integers convert
    assert np.array_equal(world.omega, np.arange(n, dtype=float))


def test_a_view_keeps_its_world_alive():
    view = rbsim.World(rbsim.load_scene(CANTILEVER)).vy
    gc.collect()
    assert np.isfinite(view).all() and view.shape[0] > 0
    view[:] = 2.0  # the memory is still the (now unnamed) World's
    assert (view == 2.0).all()


def test_divergence_is_an_error_naming_the_body():
    world = rbsim.load_scene(CANTILEVER).world()
    world.vx[2] = np.inf
    with pytest.raises(rbsim.DivergenceError, match=r"step 1: body 2 x is not finite"):
        world.step()


def test_step_releases_the_gil():
    world = rbsim.load_scene(CANTILEVER).world()
    ticks = []
    stop = threading.Event()

    def tick():
        while not stop.is_set() and len(ticks) < 1_000_000:
            ticks.append(1)

    t = threading.Thread(target=tick)
    t.start()
    world.step(200_000)
    stop.set()
    t.join(10)
    assert len(ticks) > 1000, "the other thread ran while the World stepped"


# --- commands --------------------------------------------------------------------------------------

def test_parameters_and_impulses_act_as_commands_do(tmp_path):
    steer = tmp_path / "steer.yaml"
    steer.write_text("- {step: 0, set: {forces.0.fy: -2.5, springs.1.k: 40.0}}\n"
                     "- {step: 20, impulse: {body: 3, j: [0.5, 4], p: [0.1, 0]}}\n")
    cli("run", CANTILEVER, "--steps", 60, "--commands", steer, "--csv", tmp_path / "b.csv", "-q")
    rows = read_csv(tmp_path / "b.csv")
    world = rbsim.load_scene(CANTILEVER).world()
    world.set_parameter("forces.0.fy", -2.5)
    world.set_parameter("springs.1.k", 40)  # an int for a double parameter
    world.step(20)
    world.apply_impulse(3, (0.5, 4.0), (0.1, 0.0))
    world.step(40)
    n = world.body_count
    for c in COLUMNS:
        assert np.array_equal(getattr(world, c), [r[c] for r in rows[60 * n:]]), c
    assert world.get_parameter("forces.0.fy") == -2.5 and world.parameters()["springs.1.k"] == 40.0


def test_bad_commands_are_refused_and_change_nothing():
    world = rbsim.load_scene(CANTILEVER).world()
    with pytest.raises(KeyError, match="no parameter 'forces.99.fx'"):
        world.set_parameter("forces.99.fx", 1.0)
    with pytest.raises(rbsim.Error, match="read-only|read only"):
        world.set_parameter("dt", 0.5)
    with pytest.raises(rbsim.Error, match="type"):
        world.set_parameter("springs.0.k", "stiff")
    with pytest.raises(rbsim.Error, match="rate"):
        world.set_parameter("rate", 2.0)
    with pytest.raises(TypeError):
        world.set_parameter("springs.0.k", [1.0])
    with pytest.raises(IndexError, match="body 7 is not in"):
        world.apply_impulse(7, (0, 1))
    with pytest.raises(rbsim.Error):
        world.apply_impulse(0, (float("nan"), 1))
    fresh = rbsim.load_scene(CANTILEVER).world()
    assert world.parameters() == fresh.parameters()
    assert all(np.array_equal(getattr(world, c), getattr(fresh, c)) for c in COLUMNS)


# --- recordings and checks ------------------------------------------------------------------------

def test_recording_reads_what_the_csv_holds(tmp_path):
    cli("run", CANTILEVER, "--steps", 120, "--record", tmp_path / "bag", "--csv", tmp_path / "b.csv",
        "--energy-csv", tmp_path / "e.csv", "-q")
    rec = rbsim.Recording(tmp_path / "bag")
    bodies, energy = read_csv(tmp_path / "b.csv"), read_csv(tmp_path / "e.csv")
    n = rec.scene["body_count"]
    states = rec.body_states
    assert states.x.shape == (121, n) and list(states.step) == list(range(121))
    for c in COLUMNS:
        assert np.array_equal(states[c].ravel(), [r[c] for r in bodies]), c
    assert np.array_equal(states.t, [r["t"] for r in energy])
    for c in ["U", "T_point", "T_spin", "T", "E", "U_gravity", "U_spring", "px", "py", "L"]:
        assert np.array_equal(rec.energy[c], [r[c] for r in energy]), c
    springs = rec.spring_states
    assert springs.length.shape == (121, rec.scene["spring_count"])
    assert rec.body_states is states, "each topic is read once"
    world = rbsim.load_scene(CANTILEVER).world()
    assert np.array_equal(rec.scene["mass"], world.mass)


def test_recording_of_a_changing_world_has_a_column_per_body_id(tmp_path):
    (tmp_path / "ball.xml").write_text(
        '<scene><rigidbodyvertex x="-0.1" y="0" m="1"/><rigidbodyvertex x="0.1" y="0" m="1"/>'
        '<rigidbody p="0" p="1" vx="0.5" vy="0" omega="0" r="0.05"/></scene>\n')
    (tmp_path / "c.yaml").write_text(
        "- {step: 10, spawn: {file: ball.xml, name: ball, x: [0.5, 2.0], theta: 0.25}}\n"
        "- {step: 20, delete: body_4}\n")
    rbsim.run(SOURCE / "scenes/chain.xml", steps=30, record=tmp_path / "r.mcap", csv=tmp_path / "b.csv",
              commands=tmp_path / "c.yaml")
    states = rbsim.Recording(tmp_path / "r.mcap").body_states
    assert list(states.ids) == [0, 1, 2, 3, 4, 5]
    assert states.x.shape == (31, 6)
    rows = read_csv(tmp_path / "b.csv")
    column = {int(i): k for k, i in enumerate(states.ids)}
    for c in COLUMNS:
        expected = np.full((31, 6), np.nan)
        for r in rows:
            expected[int(r["step"]), column[int(r["body"])]] = r[c]
        assert np.array_equal(states[c], expected, equal_nan=True), c
    assert np.isnan(states.x[:10, 5]).all() and not np.isnan(states.x[10:, 5]).any()
    assert np.isnan(states.x[20:, 4]).all() and not np.isnan(states.x[:20, 4]).any()
    assert rbsim.Recording(tmp_path / "r.mcap").energy.ids is None


def test_recording_errors_name_the_file(tmp_path):
    junk = tmp_path / "junk.mcap"
    junk.write_bytes(b"not an mcap file at all")
    with pytest.raises(rbsim.Error, match="junk.mcap"):
        rbsim.Recording(junk)
    with pytest.raises(rbsim.Error, match="missing.mcap"):
        rbsim.Recording(tmp_path / "missing.mcap")
    rbsim.run(CANTILEVER, steps=5, record=tmp_path / "only.mcap", topics=["body_states"])
    rec = rbsim.Recording(tmp_path / "only.mcap")
    with pytest.raises(rbsim.Error, match="no energy topic"):
        rec.energy


def test_check_matches_rbsim_check(tmp_path):
    golden, same, steered = (tmp_path / n for n in ("golden.mcap", "same.mcap", "steered.mcap"))
    steer = tmp_path / "steer.yaml"
    steer.write_text("- {step: 50, impulse: {body: 0, j: [0, 1e-3], p: [0, 0]}}\n")
    rbsim.run(CANTILEVER, steps=100, record=golden)
    rbsim.run(CANTILEVER, steps=100, record=same)
    rbsim.run(CANTILEVER, steps=100, record=steered, commands=steer)
    ok = rbsim.check(same, golden)
    assert ok and ok.passed and ok.first is None and ok.messages > 0
    bad = rbsim.check(steered, golden, topics=["body_states"])
    assert not bad
    assert bad.first["topic"] == "/rbsim/body_states" and bad.first["step"] == 51
    assert bad.first["field"].startswith("bodies[0].")
    assert any(f["over"] > 0 for f in bad.fields)
    p = subprocess.run([EXE, "check", steered, golden, "--topics", "body_states"], capture_output=True, text=True)
    assert p.returncode == 1 and bad.first["line"] in p.stdout
    loose = rbsim.check(steered, golden, topics=["body_states"], atol=1.0)
    assert loose and "passed" in str(loose).lower() or loose.passed
    with pytest.raises(rbsim.Error, match="nothing.mcap"):
        rbsim.check(tmp_path / "nothing.mcap", golden)


# --- errors and documentation -----------------------------------------------------------------------

def test_scene_errors_carry_file_line_node_attribute_rule(tmp_path):
    lines = CANTILEVER.read_text().splitlines(keepends=True)
    line = next(i for i, text in enumerate(lines) if "<rigidbodyvertex" in text)
    lines[line] = re.sub(r' m="[^"]*"', ' m="-1"', lines[line])
    bad = tmp_path / "bad.xml"
    bad.write_text("".join(lines))
    with pytest.raises(rbsim.SceneError) as e:
        rbsim.load_scene(bad)
    err = e.value
    assert err.file == str(bad) and err.line == line + 1
    assert err.node == "rigidbodyvertex" and err.attribute == "m" and "> 0" in err.rule
    assert str(err) == f"{bad}:{line + 1}: <rigidbodyvertex> attribute 'm': {err.rule}"
    with pytest.raises(rbsim.SceneError) as e:
        rbsim.load_scene(tmp_path / "none.xml")
    assert e.value.line == 0 and "none.xml" in str(e.value)
    with pytest.raises(TypeError):
        rbsim.load_scene(42)
    with pytest.raises(rbsim.SceneError):
        rbsim.run(bad)
    assert isinstance(e.value, ValueError) and isinstance(e.value, rbsim.Error)


def test_help_and_stubs_document_the_api():
    doc = rbsim.World.__doc__ + rbsim.World.step.__doc__
    assert "views" in doc and "GIL" in doc
    stub = Path(rbsim.__file__).with_name("_rbsim.pyi").read_text()
    for name in ["class World", "def step(self, n: int = 1)", "class Scene", "def load_scene", "def check"]:
        assert name in stub, name
    assert "Advances n steps" in stub
    assert rbsim.__version__.count(".") == 2
