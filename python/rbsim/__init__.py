"""rbsim: a 2D rigid-body simulator, its recordings and its checks, from Python.

    import rbsim
    scene = rbsim.load_scene("scenes/cantilever.xml")
    world = scene.world()
    world.step(1000)            # the GIL is released while it steps
    world.x, world.vy           # NumPy views of the World's own state (no copies)
    world.energy()              # the energy CSV's columns: U, T_point, T_spin, T, E, ...

    rbsim.run("scene.xml", steps=500, record="run.mcap")   # = rbsim run scene.xml --steps 500 --record run.mcap
    rec = rbsim.Recording("run.mcap")                       # a file or a rosbag2 bag directory
    rec.body_states.x                                       # steps x bodies, read on first use
    result = rbsim.check("run.mcap", "golden.mcap")         # falsy on a divergence; str() is the report

The simulation is the C++ library's (the same code as the `rbsim` command), so a run from Python
gives the same bits as the command line.
"""
import functools
import os

from . import _rbsim
from ._errors import DivergenceError, Error, SceneError
from ._rbsim import CheckResult, Scene, World, check, load_scene

__version__ = _rbsim.__version__
__all__ = [
    "CheckResult",
    "DivergenceError",
    "Error",
    "Recording",
    "Scene",
    "SceneError",
    "Table",
    "World",
    "check",
    "load_scene",
    "run",
]


def run(scene, *, steps=None, duration=None, csv=None, energy_csv=None, fosssim_out=None, record=None,
        record_every=1, compression="zstd", compression_level=0, namespace="rbsim", topics=None,
        commands=None, overwrite=False, allow_nonfinite=False):
    """Runs a scene and writes its outputs exactly as ``rbsim run`` does, byte for byte.

    scene: a path (or a Scene: its file). steps, or duration in simulated seconds (ceil(T / dt)
    steps); the scene's duration by default. csv, energy_csv, fosssim_out, record: the outputs of
    ``--csv``, ``--energy-csv``, ``--fosssim-out`` and ``--record`` (a path ending in .mcap, else a
    rosbag2 bag directory). commands: a YAML script or a recording of a steered session, as
    ``--commands``. Existing outputs are refused unless overwrite=True. Returns the steps done.

    Raises SceneError for a bad scene, DivergenceError when the state stops being finite (the
    outputs then hold the steps before it), Error for anything else; KeyboardInterrupt on Ctrl-C,
    once the outputs hold the steps done.
    """
    if isinstance(scene, Scene):
        scene = scene.path
    if isinstance(topics, str):
        topics = [topics]
    return _rbsim._run(scene, steps, duration, csv, energy_csv, fosssim_out, record, record_every, compression,
                       compression_level, namespace, None if topics is None else list(topics), commands,
                       overwrite, allow_nonfinite)


class Table:
    """Columns of one recorded topic, as NumPy arrays: by attribute (``t.x``) or by name (``t["x"]``).

    ``step``, ``t`` (``step * dt``, the CSV's t, with the dt of the step's world) and ``segment`` (0,
    then one more each time the steps start again at 0: a reset, a world loaded) have one entry per
    recorded step, in the session's order; per-body and
    per-spring columns are steps x bodies (or springs), scene-wide ones one per step. ``ids`` names
    the bodies (springs) of the columns: every id the recording holds, increasing (a scene's own
    0..n-1); where bodies came or went (spawned, deleted) a column is NaN at the steps its body was
    not there. None for scene-wide topics.
    """

    def __init__(self, topic, columns, ids=None):
        self.topic = topic
        self.ids = ids
        self._columns = columns

    @property
    def names(self):
        """The column names."""
        return list(self._columns)

    def __getitem__(self, name):
        return self._columns[name]

    def __getattr__(self, name):
        try:
            return self.__dict__["_columns"][name]
        except KeyError:
            raise AttributeError(f"{self.topic} has no column {name!r} (it has {', '.join(self._columns)})") from None

    def __len__(self):
        return len(self._columns["step"])

    def __repr__(self):
        return f"<rbsim.Table {self.topic}: {len(self)} steps, columns {', '.join(self._columns)}>"


class Recording:
    """A recording (an MCAP file or a rosbag2 bag directory) read through rbsim's one reader.

    Opening reads only the scene description; each per-step topic is read whole on first use:
    ``body_states`` (x, y, theta, vx, vy, omega: steps x bodies), ``spring_states`` (end_i_x ...
    potential: steps x springs) and ``energy`` (U, T_point, T_spin, T, E, U_gravity, U_spring, px,
    py, L: one per step), each with ``step`` and ``t``. namespace chooses among several nodes'
    topics in one file. Raises Error for an unreadable file, naming it and what is wrong.
    """

    def __init__(self, path, namespace=None):
        self.path = os.fspath(path)
        self.namespace = namespace or ""
        info = _rbsim._recording_info(self.path, self.namespace)
        self.scene = info["scene"]
        self.topics = info["topics"]
        self._per_step = info["per_step"]

    def _read(self, topic):
        if not self._per_step[topic]:
            raise Error(f"{self.path}: has no {topic} topic (its topics: {', '.join(self.topics)})")
        columns = _rbsim._read_topic(self.path, self.namespace, topic)
        return Table(self._per_step[topic], columns, columns.pop("id", None))

    @functools.cached_property
    def body_states(self):
        """x, y, theta, vx, vy, omega per recorded step and body (read on first use)."""
        return self._read("body_states")

    @functools.cached_property
    def spring_states(self):
        """Spring endpoints, length, rest length and potential per recorded step and spring."""
        return self._read("spring_states")

    @functools.cached_property
    def energy(self):
        """The energy CSV's columns per recorded step: U, T_point, T_spin, T, E, U_gravity, U_spring, px, py, L."""
        return self._read("energy")

    def __repr__(self):
        s = self.scene
        return f"<rbsim.Recording {self.path}: {s['name']}, {s['body_count']} bodies, dt {s['dt']}>"
