r"""Parameter sweeps: many runs of one scene with varied parameters, spread over a Ray cluster.

A sweep file (TOML) names a base scene, the simulated seconds and the scene keys to vary::

    scene = "sample"                   # a built-in name, or a .toml path relative to this file
    seconds = 2.0
    mode = "grid"                      # every combination; "random": `samples` draws
    seed = 0                           # random mode only

    [parameters]
    "physics.stiffness" = [500, 1000, 2000]
    "body[0].position" = [[0, 2], [1, 2]]
    # random mode: { min = 0.1, max = 0.9 } draws uniformly (vectors too: min = [0, 2], max = [1, 3])

Every run's scene is the base scene's TOML with the run's values set at their key paths, read
by the scene loader's own validation (:func:`deforma.scene.parse_scene`) before anything
runs. Each run gets a stable id, a status (``ok``, ``unstable`` with the hint, ``error`` with
the message), metrics, and one row in ``OUTDIR/results.parquet``, a folder of Parquet parts
(one per finished run, written atomically) that pyarrow and pandas read as one table; on
request also its states (``OUTDIR/states/``) and a video (``OUTDIR/videos/``).

``docs/sweeps.md`` describes the table and how to point a sweep at a cluster.

Examples
--------
>>> from pathlib import Path
>>> from deforma.sweeps import load_spec, plan
>>> _ = Path("drop.toml").write_text('scene = "sample"\nseconds = 1.0\n[parameters]\n'
...                                  '"physics.friction" = [0.1, 0.5]\n"body[0].position" = [[0, 2], [1, 2]]\n')
>>> runs = plan(load_spec("drop.toml"))
>>> [(r.parameters["physics.friction"], r.parameters["body[0].position"]) for r in runs]
[(0.1, [0, 2]), (0.1, [1, 2]), (0.5, [0, 2]), (0.5, [1, 2])]
"""

from __future__ import annotations

import copy
import difflib
import hashlib
import itertools
import json
import math
import os
import re
import socket
import sys
import time
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable

if TYPE_CHECKING:
    import pyarrow as pa

    from .scene import Scene

__all__ = ["Run", "SweepError", "SweepResult", "SweepSpec", "connect", "load_spec", "plan", "sweep"]

#: The keys a sweep file may have at its top level.
SPEC_KEYS = ("scene", "seconds", "mode", "samples", "seed", "parameters")
MODES = ("grid", "random")
#: Largest number of runs one sweep file may plan, refused from the count alone before anything
#: is built. Planning and checking cost about 0.5 ms a run before the first one starts (a
#: million: minutes and 400 MB); 10000 runs take a few seconds. More runs: several sweep files
#: with the same scene, seconds and keys (other values or seeds) write into the same table.
MAX_RUNS = 10_000
#: How long to wait for a TCP answer from ``--address`` before saying it is unreachable (Ray
#: itself retries an unreachable head for minutes).
CONNECT_TIMEOUT = 10.0
#: A run is at rest while the fastest vertex of every body moves slower than this (m/s):
#: 1 cm/s, a third of a millimetre per frame at 30 fps: no visible motion in a video of a scene a
#: few metres across. See :func:`simulate` (``time_to_rest_s``).
REST_SPEED = 0.01
RESULTS_NAME = "results.parquet"
STATES_FOLDER = "states"
VIDEOS_FOLDER = "videos"
VIDEO_FORMATS = ("mp4", "gif")
#: A run's video, in pixels: half of ``deforma run``'s 1280x720, as many videos are drawn on
#: the workers' CPUs (software OpenGL when there is no GPU).
VIDEO_SIZE = (640, 360)

_KEY_PATH = re.compile(r"^([A-Za-z_]\w*)(?:\[(\d+)\])?\.([A-Za-z_]\w*)$")


class SweepError(ValueError):
    """A sweep that cannot run as given: one line naming the file, the key path or run, and what is allowed."""


@dataclass(frozen=True)
class SweepSpec:
    """A validated sweep file."""

    path: Path
    scene: str                 # the base scene as written (built-in name or path)
    scene_file: Path           # the scene file it names
    scene_data: dict           # the base scene's TOML, as read
    seconds: float
    mode: str
    samples: int | None
    seed: int
    parameters: dict           # key path -> list of values, or {"min": ..., "max": ...}

    @property
    def fingerprint(self) -> str:
        """What makes two tables comparable: the base scene's content, the seconds and the key paths varied."""
        text = json.dumps([self.scene_data, self.seconds, sorted(self.parameters)], sort_keys=True, default=str)
        return hashlib.sha256(text.encode()).hexdigest()[:16]


@dataclass(frozen=True)
class Run:
    """One run of a sweep: its id and the values it sets."""

    run_id: str
    index: int
    parameters: dict


@dataclass(frozen=True)
class SweepResult:
    """What :func:`sweep` did: runs planned, skipped (already in the table), run now, by status."""

    total: int
    skipped: int
    ran: int
    ok: int
    unstable: int
    error: int
    table: Path


# -- the sweep file -------------------------------------------------------------------------------
def _read_toml(path: Path, what: str) -> dict:
    try:
        import tomllib
    except ModuleNotFoundError:  # Python < 3.11
        import tomli as tomllib  # type: ignore[no-redef]
    try:
        return tomllib.loads(path.read_bytes().decode("utf-8"))
    except OSError as e:
        raise SweepError(f"{path}: cannot read the {what} ({e.strerror or e})") from None
    except UnicodeDecodeError:
        raise SweepError(f"{path}: not a text file (a {what} is TOML in UTF-8)") from None
    except tomllib.TOMLDecodeError as e:
        raise SweepError(f"{path}: invalid TOML: {e}") from None
    except ValueError:  # an integer past Python's 4300 digits: the reader's int() refuses it
        raise SweepError(f"{path}: invalid TOML: an integer of more than {sys.get_int_max_str_digits()} digits "
                         f"(every number in a {what} is far smaller)") from None


def _is_number(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def _finite_range(lo, hi) -> bool:
    """Whether ``[lo, hi]`` can be drawn from uniformly: finite ends in order and a finite
    width (``{min = 0, max = inf}`` or ``{min = -1e308, max = 1e308}`` overflowed NumPy's
    draw with a traceback)."""
    try:
        lo, hi = float(lo), float(hi)
    except OverflowError:  # an integer beyond any float
        return False
    return math.isfinite(lo) and math.isfinite(hi) and lo <= hi and math.isfinite(hi - lo)


def _count(n: int) -> str:
    """A run count for a message (str() of one past 4300 digits would fail)."""
    return str(n) if n < 10**100 else "over 1e100"


def load_spec(path: str | os.PathLike[str]) -> SweepSpec:
    """Read and check a sweep file: its own keys, the base scene, and every key path and value.

    Raises
    ------
    SweepError
        One line: an unknown key or key path (with "did you mean"), an empty parameter list, a
        bad range, or a value the scene loader refuses (with its key path and the run).
    """
    from .scene.assets import scene_path

    path = Path(path)
    name = path.name
    data = _read_toml(path, "sweep file")
    for key in data:
        if key not in SPEC_KEYS:
            close = difflib.get_close_matches(key, SPEC_KEYS, n=1)
            hint = f"did you mean {close[0]!r}? " if close else ""
            raise SweepError(f"{name}: {key}: unknown key; {hint}allowed: {', '.join(SPEC_KEYS)}")
    if not isinstance(data.get("scene"), str) or not data["scene"]:
        raise SweepError(f"{name}: scene: missing; give a built-in scene name or a .toml path relative to "
                         f"this file")
    scene = data["scene"]
    from .scene.assets import builtin_scenes

    ref = scene if scene in builtin_scenes() else str((path.parent / scene))
    try:
        scene_file = scene_path(ref)
    except ValueError as e:
        raise SweepError(f"{name}: scene: {e}") from None
    scene_data = _read_toml(scene_file, "scene file")

    seconds = data.get("seconds")
    if seconds is None:
        raise SweepError(f"{name}: seconds: missing; give the simulated time of each run in seconds")
    if not _is_number(seconds) or not (0 < seconds <= 3600) or not math.isfinite(seconds):
        raise SweepError(f"{name}: seconds: expected a number in (0, 3600], got {seconds!r}")
    mode = data.get("mode", "grid")
    if mode not in MODES:
        raise SweepError(f"{name}: mode: unknown value {mode!r}; allowed: {', '.join(MODES)}")
    samples = data.get("samples")
    if mode == "random":
        if not isinstance(samples, int) or isinstance(samples, bool) or samples < 1:
            raise SweepError(f"{name}: samples: random mode needs a whole number of runs in [1, {MAX_RUNS}], "
                             f"got {samples!r}")
        if samples > MAX_RUNS:
            raise SweepError(f"{name}: samples: {_count(samples)} runs; a sweep file plans at most {MAX_RUNS} "
                             f"(more: several files with other seeds, into the same output folder)")
    elif samples is not None:
        raise SweepError(f"{name}: samples: only for mode = \"random\" (grid runs every combination)")
    seed = data.get("seed", 0)
    if not isinstance(seed, int) or isinstance(seed, bool) or seed < 0:
        raise SweepError(f"{name}: seed: expected a whole number >= 0, got {seed!r}")

    params = data.get("parameters")
    if not isinstance(params, dict) or not params:
        raise SweepError(f"{name}: [parameters]: missing or empty; give at least one scene key path, like "
                         f"\"physics.stiffness\" = [500, 1000]")
    for key, values in params.items():
        where = f'{name}: [parameters] "{key}"'
        if isinstance(values, dict):
            if mode != "random":
                raise SweepError(f"{where}: a range {{ min, max }} needs mode = \"random\"; in grid mode give a "
                                 f"list of values")
            if set(values) != {"min", "max"}:
                raise SweepError(f"{where}: a range has exactly the keys min and max, got {', '.join(values)}")
            lo, hi = values["min"], values["max"]
            if _is_number(lo) and _is_number(hi):
                ok = _finite_range(lo, hi)
            elif isinstance(lo, list) and isinstance(hi, list) and len(lo) == len(hi) and lo:
                ok = all(_is_number(a) and _is_number(b) and _finite_range(a, b) for a, b in zip(lo, hi))
            else:
                ok = False
            if not ok:
                raise SweepError(f"{where}: a range needs finite numbers (or equally long lists of them) with "
                                 f"min <= max and a finite width, got min = {lo!r}, max = {hi!r}")
        elif isinstance(values, list):
            if not values:
                raise SweepError(f"{where}: empty list; give at least one value")
        else:
            raise SweepError(f"{where}: expected a list of values"
                             + (" or a range { min, max }" if mode == "random" else "") + f", got {values!r}")

    spec = SweepSpec(path=path, scene=scene, scene_file=Path(scene_file), scene_data=scene_data,
                     seconds=float(seconds), mode=mode, samples=samples, seed=seed, parameters=params)
    # each key path with its first value, so a typo is named once, by its key path
    for key, values in params.items():
        first = values[0] if isinstance(values, list) else values["min"]
        scene_for(spec, {key: first}, source=f"{name}: [parameters]")
    runs = plan(spec)
    for run in runs:
        scene_for(spec, run.parameters, source=f"{name}: run {run.index} ({run.run_id})")
    return spec


def _set_key(data: dict, key: str, value, source: str) -> None:
    """Set ``value`` at the key path ``key`` (``section.key`` or ``array[i].key``) of a scene dict."""
    from .scene.schema import ARRAYS, SECTIONS

    m = _KEY_PATH.match(key)
    tables = list(SECTIONS) + [f"{a}[i]" for a in ARRAYS]
    if not m:
        raise SweepError(f"{source}: {key}: not a key path; write section.key (like physics.stiffness) or "
                         f"array[index].key (like body[0].position)")
    table, index, name = m.group(1), m.group(2), m.group(3)
    if table in ARRAYS:
        items = data.get(table)
        if index is None:
            raise SweepError(f"{source}: {key}: [[{table}]] is an array of tables; say which one, like {table}[0].{name}")
        count = len(items) if isinstance(items, list) else 0
        if int(index) >= count:
            raise SweepError(f"{source}: {key}: the scene has {count} [[{table}]] table{'s' if count != 1 else ''}"
                             + (f" (indices 0 to {count - 1})" if count else ""))
        items[int(index)][name] = value  # type: ignore[index]  # a list: count > index
    elif table in SECTIONS:
        if index is not None:
            raise SweepError(f"{source}: {key}: [{table}] is a table, not an array; write {table}.{name}")
        data.setdefault(table, {})[name] = value
    else:
        close = difflib.get_close_matches(table, list(SECTIONS) + list(ARRAYS), n=1)
        hint = f"did you mean {close[0]!r}? " if close else ""
        raise SweepError(f"{source}: {key}: unknown table {table!r}; {hint}allowed: {', '.join(tables)}")


def scene_for(spec: SweepSpec, parameters: dict, *, source: str) -> Scene:
    """The base scene with ``parameters`` set, validated by the scene loader; raises SweepError."""
    from .scene.schema import parse_scene

    data = copy.deepcopy(spec.scene_data)
    for key, value in parameters.items():
        _set_key(data, key, value, source)
    data.setdefault("run", {})["seconds"] = spec.seconds
    try:
        scene = parse_scene(data, source=source, base_dir=spec.scene_file.resolve().parent)
    except ValueError as e:
        raise SweepError(str(e)) from None
    return replace(scene, path=str(spec.scene_file.resolve()))


def _plain(value):
    """A value as JSON would keep it: tuples as lists, integral floats of ints left alone."""
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    return value


def run_id(spec: SweepSpec, parameters: dict) -> str:
    """A run's stable id: a hash of the spec's fingerprint and the run's values."""
    text = json.dumps([spec.fingerprint, {k: _plain(v) for k, v in sorted(parameters.items())}], sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()[:12]


def plan(spec: SweepSpec) -> list[Run]:
    """The runs of a sweep, in order: every combination (grid) or ``samples`` draws (random)."""
    keys = list(spec.parameters)
    if spec.mode == "grid":
        count = math.prod(len(spec.parameters[k]) for k in keys)
        if count > MAX_RUNS:  # from the list lengths alone, before any combination is built
            raise SweepError(f"{spec.path.name}: [parameters]: {_count(count)} combinations; a sweep file plans at "
                             f"most {MAX_RUNS} runs (more: split the lists over several files, into the same "
                             f"output folder)")
        combos = [dict(zip(keys, values)) for values in itertools.product(*(spec.parameters[k] for k in keys))]
    else:
        import numpy as np

        rng = np.random.default_rng(spec.seed)
        combos = []
        for _ in range(spec.samples):  # type: ignore[arg-type]  # random mode: load_spec set it
            combo = {}
            for k in keys:
                v = spec.parameters[k]
                if isinstance(v, dict):
                    drawn = rng.uniform(v["min"], v["max"])
                    # an array when min and max are lists
                    combo[k] = drawn.tolist() if isinstance(v["min"], list) else float(drawn)  # type: ignore[attr-defined]
                else:
                    combo[k] = v[int(rng.integers(len(v)))]
            combos.append(combo)
    runs, seen = [], set()
    for i, combo in enumerate(combos):
        rid = run_id(spec, combo)
        if rid in seen:  # the same values twice (a list with a repeat): one run
            continue
        seen.add(rid)
        runs.append(Run(run_id=rid, index=i, parameters=combo))
    return runs


# -- one run (on a Ray worker) -------------------------------------------------------------------
def _largest_spring_strain(world) -> float:
    import numpy as np

    largest = 0.0
    for b in world.bodies:
        springs = np.asarray(b.springs)
        if len(springs) == 0:
            continue
        x, rest = b.positions, np.asarray(b.topology.rest_positions)
        i, j = springs[:, 0], springs[:, 1]
        # np.take: gathers (N, 2) rows ~10x faster than x[springs[:, k]] (every frame)
        now = np.linalg.norm(np.take(x, j, axis=0) - np.take(x, i, axis=0), axis=1)
        was = np.linalg.norm(np.take(rest, j, axis=0) - np.take(rest, i, axis=0), axis=1)
        ok = was > 0
        if ok.any():
            largest = max(largest, float(np.max(np.abs(now[ok] / was[ok] - 1.0))))
    return largest


def _largest_speed(world) -> float:
    import numpy as np

    return max((float(np.max(np.hypot(v[:, 0], v[:, 1]))) for v in (b.velocities for b in world.bodies)
                if len(v)), default=0.0)


class _NoVideo(Exception):
    """A video was asked for and cannot be drawn here (no OpenGL, no moderngl): the run's error."""


def _video_view(world, size):
    """A headless renderer bound to ``world`` (``deforma run -o``'s), or :class:`_NoVideo` saying why not."""
    try:
        from .render import Renderer, WorldView
    except ImportError as e:
        raise _NoVideo(f"no video: the renderer needs moderngl ({e}); pip install 'deforma[render]'") from None
    try:
        renderer = Renderer.headless(size)
    except RuntimeError as e:
        raise _NoVideo("no video: " + " ".join(str(e).split())) from None
    try:
        return WorldView(renderer, world)
    except BaseException:
        renderer.release()
        raise


def simulate(scene: Scene, *, states: bool | str | os.PathLike[str] = False, video: str | None = None,
             video_size: tuple[int, int] = VIDEO_SIZE) -> dict:
    """Run one scene for its ``run.seconds``; the row's status, message and metrics (and the states NPZ
    and video bytes).

    ``states``: ``False``, or the folder the states NPZ will be kept in (``True``: the working
    folder), which its scene's texture files are named relative to.

    Never raises for the simulation's sake: an unstable world is ``status = "unstable"`` with its
    hint, any other exception ``status = "error"`` with its message.

    ``time_to_rest_s`` is the simulated time of the first frame (at the scene's ``run.fps``)
    from which on, up to and including the last frame, no vertex of any body moves faster than
    :data:`REST_SPEED`; NaN if the last frame is not at rest (the bodies never settle, or
    settle and are thrown again). Only frames are looked at, so a bounce that turns exactly
    at the last frame would count as rest there: give a run some time after it settles.

    With ``video`` (``"mp4"`` or ``"gif"``) every frame is also drawn, ``video_size`` pixels, by
    ``deforma run -o``'s renderer and writer; ``row["video"]`` holds the file's bytes for an
    ok run. Where no OpenGL context can be made the run is not simulated: ``status = "error"``
    with a message that starts ``no video:`` and says what to install.
    """
    import shutil
    import tempfile

    import numpy as np

    from .physics import SimulationUnstable
    from .scene.playback import Playback, frame_count

    t0 = time.perf_counter()
    row = {"status": "ok", "message": "", "hint": "", "steps": 0, "simulated_s": 0.0, "final_energy_j": math.nan,
           "max_spring_strain": math.nan, "time_to_rest_s": math.nan, "centroid": [], "worker": socket.gethostname(),
           "states": None}
    world = view = writer = folder = None
    try:
        world = scene.build()
        fps = scene.run.fps
        if video is not None:
            from .render import open_writer

            view = _video_view(world, video_size)  # before the simulation: without GL, fail at once
            folder = Path(tempfile.mkdtemp(prefix="deforma-sweep-"))
            writer = open_writer(folder / f"video.{video}", fps=fps)
        playback = Playback(scene, world, fps=fps, view=view, writer=writer, record=bool(states))
        strain = 0.0
        resting_since = None  # the first frame of the current run of frames at rest
        # frame k at k / fps, the last one at the end of the run
        for _ in playback.frames(frame_count(scene.run.seconds, fps) + 1):
            strain = max(strain, _largest_spring_strain(world))
            if _largest_speed(world) < REST_SPEED:
                resting_since = world.time if resting_since is None else resting_since
            else:
                resting_since = None
        row["max_spring_strain"] = strain
        row["time_to_rest_s"] = math.nan if resting_since is None else float(resting_since)
        row["final_energy_j"] = float(world.energy().total)
        row["centroid"] = [[float(v) for v in np.mean(b.positions, axis=0)] for b in world.bodies]
        if states:
            # record=True: the playback keeps a recording
            row["states"] = playback.recording.to_bytes(  # type: ignore[union-attr]
                kept_in=None if states is True else states)
        if writer is not None:
            writer.close()
            row["video"] = (folder / f"video.{video}").read_bytes()  # type: ignore[operator]  # made with writer
    except SimulationUnstable as e:
        row.update(status="unstable", message=str(e), hint=e.hint)
    except _NoVideo as e:
        row.update(status="error", message=str(e))
    except Exception as e:  # noqa: BLE001 - a run's failure is a row, never the sweep's crash
        row.update(status="error", message=f"{type(e).__name__}: {e}")
    finally:
        if writer is not None:
            writer.abort()  # no-op after close(); discards the temporary file otherwise
        if view is not None:
            view.renderer.release()
        if folder is not None:
            shutil.rmtree(folder, ignore_errors=True)
    if world is not None:
        row["steps"] = int(world.step_count)
        row["simulated_s"] = float(world.time)
    row["wall_s"] = time.perf_counter() - t0
    return row


def _worker_run(scene, states, video: str | None = None, video_size=VIDEO_SIZE) -> dict:
    # one thread per run: a worker is one of `workers` processes on the node's cores (the runtime
    # environment sets it too; this covers a cluster started without it)
    os.environ.setdefault("NUMBA_NUM_THREADS", "1")
    return simulate(scene, states=states, video=video, video_size=video_size)


# -- Ray -------------------------------------------------------------------------------------------
def _check_reachable(address: str) -> None:
    """Fail within :data:`CONNECT_TIMEOUT` when nothing listens at ``address`` (Ray would retry for minutes)."""
    if address == "auto":
        return
    hostport = address.split("://", 1)[-1].rstrip("/")
    host, _, port = hostport.rpartition(":")
    # repr() for a line break or other control character: the message stays one line
    garbage = SweepError(f"--address {address if address.isprintable() else repr(address)}: expected HOST:PORT "
                         f"(what `ray start --head` prints; a port in 1-65535), ray://HOST:PORT or auto")
    # the port as at most 5 ASCII digits: isdigit() alone takes "²", which int() refuses; the
    # resolver wraps 99999 round to another port and overflows on 20 digits (a traceback)
    if not (host and address.isprintable() and port.isascii() and port.isdigit() and len(port) <= 5
            and 0 < int(port) <= 65535):
        raise garbage
    try:
        with socket.create_connection((host.strip("[]"), int(port)), timeout=CONNECT_TIMEOUT):
            pass
    except UnicodeError:  # no host name: the resolver's IDNA codec refuses a label empty or over 63 characters
        raise garbage from None
    except OSError as e:
        raise SweepError(f"cannot reach a Ray cluster at {address} ({e.strerror or e}); start one with "
                         f"`ray start --head`, or leave out the address for a local cluster") from None


def connect(*, workers: int | None = None, address: str | None = None) -> bool:
    """Start a local Ray cluster (``workers`` CPUs) or connect to ``address``; True if this call did it.

    Nothing happens (False) when Ray is already initialised in this process: that cluster is used.
    """
    try:
        import ray
    except ImportError:
        raise SweepError("sweeps need Ray and pyarrow: pip install 'deforma[sweep]'") from None
    if ray.is_initialized():
        return False
    address = address or os.environ.get("RAY_ADDRESS") or None
    if workers is not None and (not isinstance(workers, int) or workers < 1):
        raise SweepError(f"workers: expected a whole number >= 1, got {workers!r}")
    if address:
        _check_reachable(address)
    import logging

    kwargs: dict[str, Any] = dict(include_dashboard=False, log_to_driver=False, logging_level=logging.ERROR,
                  runtime_env={"env_vars": {"NUMBA_NUM_THREADS": "1"}})
    if not address:  # num_cpus is refused when joining an existing cluster: it has its own
        kwargs["num_cpus"] = workers or os.cpu_count() or 1
    try:
        # "local": a new cluster of `workers` CPUs; None would join the last `ray start` cluster
        # of this machine, if any (Ray's auto-detection), and then refuse num_cpus
        ray.init(address=address or "local", **kwargs)
    except (ConnectionError, RuntimeError, ValueError) as e:
        first = str(e).strip().splitlines()[0] if str(e).strip() else type(e).__name__
        hint = ("; a cluster with token authentication (Ray >= 2.59 turns it on for `ray start`) also needs "
                "RAY_AUTH_MODE=token and its token here (RAY_AUTH_TOKEN or ~/.ray/auth_token)") if address else ""
        raise SweepError(f"cannot start or join a Ray cluster{f' at {address}' if address else ''}: {first}"
                         f"{hint}") from None
    return True


# -- the table -------------------------------------------------------------------------------------
def _column_type(values):
    """The Arrow type of a parameter's column, from every value the spec allows for it."""
    import pyarrow as pa

    if isinstance(values, dict):
        values = [values["min"], values["max"]]
        return pa.list_(pa.float64()) if isinstance(values[0], list) else pa.float64()
    if all(isinstance(v, int) and not isinstance(v, bool) for v in values):
        return pa.int64()
    if all(_is_number(v) for v in values):
        return pa.float64()
    if all(isinstance(v, bool) for v in values):
        return pa.bool_()
    if all(isinstance(v, list) and all(_is_number(x) for x in v) for v in values):
        return pa.list_(pa.float64())
    return pa.string()  # anything else (strings, nested tables) as JSON text


def _schema(spec: SweepSpec):
    import pyarrow as pa

    fields = [
        ("run_id", pa.string()), ("run_index", pa.int64()), ("spec_fingerprint", pa.string()),
        ("status", pa.string()), ("message", pa.string()), ("hint", pa.string()),
        ("wall_s", pa.float64()), ("steps", pa.int64()), ("simulated_s", pa.float64()),
        ("final_energy_j", pa.float64()), ("max_spring_strain", pa.float64()), ("time_to_rest_s", pa.float64()),
        ("centroid", pa.list_(pa.list_(pa.float64()))), ("states_path", pa.string()), ("video_path", pa.string()),
        ("worker", pa.string()),
        ("finished_at", pa.timestamp("s", tz="UTC")), ("parameters", pa.string()),
    ]
    fields += [(k, _column_type(v)) for k, v in spec.parameters.items()]
    return pa.schema(fields)


def _row_table(spec: SweepSpec, run: Run, row: dict, states_path: str | None, video_path: str | None = None):
    import datetime

    import pyarrow as pa

    schema = _schema(spec)
    record = {
        "run_id": run.run_id, "run_index": run.index, "spec_fingerprint": spec.fingerprint,
        "status": row["status"], "message": row["message"], "hint": row["hint"], "wall_s": row["wall_s"],
        "steps": row["steps"], "simulated_s": row["simulated_s"], "final_energy_j": row["final_energy_j"],
        "max_spring_strain": row["max_spring_strain"], "time_to_rest_s": row["time_to_rest_s"],
        "centroid": row["centroid"], "states_path": states_path, "video_path": video_path,
        "worker": row["worker"], "finished_at": datetime.datetime.now(datetime.timezone.utc),
        "parameters": json.dumps(run.parameters, sort_keys=True),
    }
    for k, v in run.parameters.items():
        record[k] = json.dumps(v) if schema.field(k).type == pa.string() else v
    return pa.Table.from_pylist([record], schema=schema)


def read_results(outdir: str | os.PathLike[str]) -> pa.Table | None:
    """The sweep table in ``outdir`` (a pyarrow Table), or None when there is none yet."""
    import pyarrow.parquet as pq

    folder = Path(outdir) / RESULTS_NAME
    if not folder.is_dir() or not any(folder.glob("part-*.parquet")):
        return None
    # parts written by different specs (--force) may have different parameter columns
    import pyarrow as pa

    tables = [pq.read_table(p) for p in sorted(folder.glob("part-*.parquet"))]
    return pa.concat_tables(tables, promote_options="default")


def _done(outdir: Path, spec: SweepSpec, *, retry_failed: bool, force: bool) -> dict:
    """run_id -> status of the runs already in the table; refuses another spec's table unless ``force``."""
    table = read_results(outdir)
    if table is None:
        return {}
    fingerprints = set(table.column("spec_fingerprint").to_pylist())
    if fingerprints - {spec.fingerprint} and not force:
        raise SweepError(f"{outdir / RESULTS_NAME}: holds runs of a different sweep (another base scene, seconds "
                         f"or parameter keys); use another output folder, or --force to add this sweep's rows "
                         f"beside them")
    done = dict(zip(table.column("run_id").to_pylist(), table.column("status").to_pylist()))
    if retry_failed:
        done = {k: s for k, s in done.items() if s == "ok"}
    return done


# -- the sweep -------------------------------------------------------------------------------------
def sweep(spec_path: str | os.PathLike[str], outdir: str | os.PathLike[str], *, workers: int | None = None,
          address: str | None = None, states: bool = False,
          video: str | bool | None = None, video_size: tuple[int, int] = VIDEO_SIZE, retry_failed: bool = False,
          force: bool = False, progress: Callable[[int, int, int], object] | None = None) -> SweepResult:
    r"""Run every run of a sweep file on Ray; one row per run in ``outdir/results.parquet``.

    Parameters
    ----------
    spec_path : path
        The sweep file (TOML; see this module's docstring and ``docs/sweeps.md``).
    outdir : path
        Folder for ``results.parquet`` (a folder of one Parquet part per run), ``states/`` and
        ``videos/``; made if missing.
    workers : int, keyword-only
        CPUs of the local cluster Ray starts (default: every core); ignored with ``address``.
    address : str, keyword-only
        A running Ray cluster (``HOST:PORT`` from ``ray start --head``, ``ray://HOST:PORT`` or
        ``auto``). An unreachable address fails within about 10 s.
    states : bool, keyword-only
        Also write each ok run's ``deforma run --states`` NPZ to ``outdir/states/RUN_ID.npz``.
    video : {"mp4", "gif"} or bool, keyword-only
        Also draw each run with ``deforma run -o``'s renderer and write each ok run's video to
        ``outdir/videos/RUN_ID.mp4`` (or ``.gif``; True means mp4). A worker without OpenGL
        makes that run an ``error`` row ("no video: ..."), not the sweep's failure.
    video_size : (int, int), keyword-only
        Width and height of the videos in pixels (default 640x360).
    retry_failed : bool, keyword-only
        Run again the runs whose rows say ``unstable`` or ``error`` (their rows are replaced).
    force : bool, keyword-only
        Add rows to a table that holds runs of a different sweep (nothing is deleted).
    progress : callable, keyword-only
        ``progress(done, total, failures)`` after each finished run (the CLI's bar).

    Returns
    -------
    SweepResult
        Counts of the runs planned, skipped (already in the table) and run now, by status.

    Raises
    ------
    SweepError
        A bad sweep file (before anything runs), another sweep's table, Ray missing or unreachable.

    Examples
    --------
    A sweep starts a local Ray cluster (about 10 s) unless given one::

        import deforma
        result = deforma.sweep("examples/friction_sweep.toml", "out", workers=2)
        print(result.ok, result.unstable, result.error)

    The file is checked before Ray starts, so a typo costs nothing:

    >>> from pathlib import Path
    >>> import deforma
    >>> _ = Path("typo.toml").write_text('scene = "sample"\nseconds = 1.0\n[parameters]\n'
    ...                                  '"physics.stifness" = [500, 1000]\n')
    >>> deforma.sweep("typo.toml", "out")
    Traceback (most recent call last):
    ...
    deforma.sweeps.SweepError: typo.toml: [parameters]: physics.stifness: unknown key; did you mean 'stiffness'? ...
    """
    video = _check_video(video, video_size)
    spec = load_spec(spec_path)
    runs = plan(spec)
    outdir = Path(outdir)
    if outdir.exists() and not outdir.is_dir():
        raise SweepError(f"{outdir}: exists and is not a folder")
    done = _done(outdir, spec, retry_failed=retry_failed, force=force)
    todo = [r for r in runs if r.run_id not in done]
    counts = {"ok": 0, "unstable": 0, "error": 0}
    result = lambda: SweepResult(total=len(runs), skipped=len(runs) - len(todo), ran=sum(counts.values()),  # noqa: E731
                                 table=outdir / RESULTS_NAME, **counts)
    if progress is not None:
        progress(len(runs) - len(todo), len(runs), 0)
    if not todo:
        return result()
    try:
        import pyarrow  # noqa: F401 - checked before the cluster starts
    except ImportError:
        raise SweepError("sweeps need Ray and pyarrow: pip install 'deforma[sweep]'") from None
    # the cluster before any folder: a bad or unreachable --address leaves nothing behind
    started = connect(workers=workers, address=address)
    import pyarrow.parquet as pq
    import ray

    from .files import write_atomic

    remote = ray.remote(num_cpus=1, max_retries=0)(_worker_run)
    pending = {}
    try:  # a folder that cannot be made still shuts down a cluster this call started
        (outdir / RESULTS_NAME).mkdir(parents=True, exist_ok=True)
        if states:
            (outdir / STATES_FOLDER).mkdir(exist_ok=True)
        if video is not None:
            (outdir / VIDEOS_FOLDER).mkdir(exist_ok=True)
        kept = str((outdir / STATES_FOLDER).resolve()) if states else False  # where the NPZs go
        for run in todo:
            scene = scene_for(spec, run.parameters, source=f"{spec.path.name}: run {run.index} ({run.run_id})")
            pending[remote.remote(scene, kept, video, tuple(video_size))] = run
        finished = len(runs) - len(todo)
        while pending:
            ready, _ = ray.wait(list(pending), num_returns=1)
            run = pending.pop(ready[0])
            try:
                row = ray.get(ready[0])
            except Exception as e:  # noqa: BLE001 - a worker that died: the run's error, not the sweep's
                first = (str(e).strip().splitlines() or [type(e).__name__])[-1]
                row = {"status": "error", "message": f"{type(e).__name__}: {first}", "hint": "", "steps": 0,
                       "simulated_s": 0.0, "final_energy_j": math.nan, "max_spring_strain": math.nan,
                       "time_to_rest_s": math.nan, "centroid": [], "worker": "", "wall_s": math.nan, "states": None}
            states_path = None
            if row.get("states") is not None:
                target = outdir / STATES_FOLDER / f"{run.run_id}.npz"
                write_atomic(target, lambda f, data=row["states"]: f.write(data))  # type: ignore[misc]
                states_path = f"{STATES_FOLDER}/{run.run_id}.npz"
            video_path = None
            if row.get("video") is not None:
                video_path = f"{VIDEOS_FOLDER}/{run.run_id}.{video}"
                write_atomic(outdir / video_path, lambda f, data=row["video"]: f.write(data))  # type: ignore[misc]
            table = _row_table(spec, run, row, states_path, video_path)
            write_atomic(outdir / RESULTS_NAME / f"part-{run.run_id}.parquet", lambda f: pq.write_table(table, f))
            counts[row["status"]] += 1
            finished += 1
            if progress is not None:
                progress(finished, len(runs), counts["unstable"] + counts["error"])
    finally:
        # Ctrl-C or a failure here: what is done stays, the rest is dropped. Runs finishing
        # this instant are let finish first (half a second at most): Ray 2.60's driver can
        # abort when a cancellation crosses a task's completion ("Check failed: it !=
        # submissible_tasks_.end() Tried to complete task that was not pending", a race like the
        # one ray-project/ray#54798 fixed for retries), and a sweep's runs, of similar length,
        # tend to finish together: Ctrl-C right after one finished hit it once in a test.
        if pending:
            try:
                _, left = ray.wait(list(pending), num_returns=len(pending), timeout=0.5)
            except BaseException:  # noqa: BLE001 - a second Ctrl-C, or Ray already gone: cancel all
                left = list(pending)
            for ref in left:
                try:
                    ray.cancel(ref, force=True)
                except Exception:  # noqa: BLE001 - already finished or gone
                    pass
        if started:
            ray.shutdown()
    return result()


def _check_video(video, size):
    """``video`` as "mp4", "gif" or None, and the size checked; SweepError otherwise."""
    if video is True:
        video = "mp4"
    elif video is False:
        video = None
    if video is not None and video not in VIDEO_FORMATS:
        raise SweepError(f"video: expected one of {', '.join(VIDEO_FORMATS)} (or True for mp4), got {video!r}")
    ok = (isinstance(size, (tuple, list)) and len(size) == 2
          and all(isinstance(v, int) and not isinstance(v, bool) for v in size))
    if not ok or not (16 <= size[0] <= 7680 and 16 <= size[1] <= 4320):
        raise SweepError(f"video_size: expected (width, height) in pixels, width in [16, 7680] and height in "
                         f"[16, 4320], got {size!r}")
    if video == "mp4":
        # each run is `deforma run -o`'s renderer and ffmpeg on a worker: the same bound, per
        # run (a GIF's frame count comes from each run's scene: its worker's row says it)
        from .render.video import check_run_memory

        try:
            check_run_memory("video.mp4", tuple(size), samples=4, frames=1, fps=30.0, size_option="--video-size",
                             who="each run of a sweep")
        except ValueError as e:
            raise SweepError(f"video_size: {str(e).split(': ', 1)[1]}") from None
    return video

