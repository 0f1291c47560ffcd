"""Run a G-code program in LinuxCNC's real motion controller, headless, and record what it commands.

:func:`run_program` writes a temporary configuration from a
:class:`~camtube.machine.MachineProfile` (INI + HAL: ``trivkins`` on the
profile's three axes, the profile's velocity and acceleration limits and servo
period, homing at zero search velocity, ``NO_FORCE_HOMING``), starts
``linuxcnc -r CONFIG.ini`` whose "display" is a small driver
(``camtube/motion/_driver.py``: estop reset, machine on, home, auto, open,
run, poll until idle), and records ``axis.<L>.pos-cmd`` of the three axes and
``motion.digital-out-NN`` (the gate) at every servo cycle with the ``sampler``
component and ``halsampler``. The ``joint.*.pos-cmd`` pins lag the axis pins
by two servo cycles, so the axis pins are the ones in step with the gate.

It runs in real time: a job of N seconds takes N seconds (plus ~2 s to start).
Under root, ``rtapi_app`` needs ``RTAPI_UID`` (another uid, 65534) and
``RTAPI_FIFO_PATH`` in a directory that uid can write; the runner sets both.
``position.txt`` is written fresh into the temporary folder before each run.
"""
from __future__ import annotations

import contextlib
import json
import math
import os
import re
import shutil
import subprocess
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from camtube.errors import CamtubeError
from camtube.inputfile import read_input_bytes

#: LinuxCNC's own Python (the ``linuxcnc`` module is built for it).
SYSTEM_PYTHON = "/usr/bin/python3"
#: A program runs in pieces of at most this many moves: LinuxCNC 2.9's task process (milltask) was seen to
#: die when it waited on a full motion queue longer than [EMCMOT] COMM_TIMEOUT, leaving the rest unrun
#: (the configuration also sets COMM_TIMEOUT far beyond any job).
PIECE_MOVES = 800
#: Stationary stretches longer than this (s) are pauses between pieces, not run time.
IDLE_S = 0.005
_CANONICAL = "XYZABCUVW"


class MotionUnavailable(CamtubeError):
    """LinuxCNC (``linuxcnc``, ``halsampler`` or its Python module) is not installed here."""


class MotionRunError(CamtubeError):
    """The controller refused or aborted the program (the message holds its errors)."""


def unavailable_reason() -> str | None:
    """Why LinuxCNC cannot run here (None when it can)."""
    for tool in ("linuxcnc", "halsampler", "halcmd"):
        if shutil.which(tool) is None:
            return f"LinuxCNC is not installed ({tool} not found; apt-get install linuxcnc-uspace)"
    if not os.path.exists(SYSTEM_PYTHON):
        return f"LinuxCNC's Python ({SYSTEM_PYTHON}) is missing"
    r = subprocess.run([SYSTEM_PYTHON, "-c", "import linuxcnc"], capture_output=True)
    if r.returncode != 0:
        return f"the linuxcnc Python module does not import in {SYSTEM_PYTHON}"
    return None


@dataclass(frozen=True, eq=False)
class Recording:
    """Commanded axis positions and the gate at kept servo cycles of one run.

    Attributes
    ----------
    cycle : (n,) int
        Servo cycle of each sample (0 = the sampler was enabled, just before the run started).
    axial, circ, focus : (n,) float
        ``axis.<L>.pos-cmd`` of the axial (mm), circumferential (deg if rotary, else mm) and
        focus (mm) axes, in the profile's axis order.
    gate : (n,) bool
        ``motion.digital-out-NN``: the beam gate, set in the same cycle as the positions: the
        gate of sample ``k`` is in force while the stage moves from sample ``k - 1`` to ``k`` (from rest,
        LinuxCNC opens it in the cycle of a cut's first step, closes it in the cycle of the next move's).
    period_s : float
        Servo period (s).
    wall_s : float
        Real time the run took (s).
    rate_khz : (n,) float or None
        Distance gating (:func:`dose_hal`): the laser's pulse rate (kHz) the HAL commands at each
        sample, in force with that sample's gate while the stage moves to that sample's position
        (from the previous one); None for a time-gated profile.
    """

    cycle: np.ndarray
    axial: np.ndarray
    circ: np.ndarray
    focus: np.ndarray
    gate: np.ndarray
    period_s: float
    wall_s: float
    rate_khz: np.ndarray | None = None

    def __len__(self) -> int:
        return len(self.cycle)

    def motion_span(self) -> tuple[int, int]:
        """(first, last) sample index at which the commanded position changes."""
        p = np.stack([self.axial, self.circ, self.focus], 1)
        moved = np.flatnonzero(np.any(np.abs(np.diff(p, axis=0)) > 0, axis=1))
        if len(moved) == 0:
            return 0, 0
        return int(moved[0]), int(moved[-1] + 1)

    @property
    def run_time_s(self) -> float:
        """Time from the first to the last servo cycle with motion (s), without idle pauses.

        A long program runs in pieces (:func:`split_program`); the controller rests a few
        milliseconds between them. Stationary stretches longer than :data:`IDLE_S` are left out
        (within a piece the machine never rests that long: an exact stop lasts a cycle or two).
        """
        a, b = self.motion_span()
        p = np.stack([self.axial, self.circ, self.focus], 1)[a:b + 1]
        c = self.cycle[a:b + 1]
        still = np.all(np.diff(p, axis=0) == 0, axis=1)
        dt = np.diff(c) * self.period_s
        # runs of consecutive stationary intervals
        edges = np.flatnonzero(np.diff(np.concatenate(([0], still.astype(np.int8), [0]))))
        idle = 0.0
        for lo, hi in zip(edges[::2], edges[1::2]):
            d = float(dt[lo:hi].sum())
            if d > IDLE_S:
                idle += d
        return float(c[-1] - c[0]) * self.period_s - idle


def _coordinates(profile) -> str:
    return "".join(sorted(profile.axes, key=_CANONICAL.index))


def _ini_number(value: float) -> str:
    """``value`` as the INI file gives it to LinuxCNC: every digit of the profile's number (``{:g}`` kept six, so a
    limit of 33.3333333 mm/s was written 33.3333), in plain decimal (no exponent: 1e6 is 1000000)."""
    return np.format_float_positional(float(value), trim="-")


def config_texts(profile, workdir: str | os.PathLike, driver: str) -> dict[str, str]:
    """File name -> text of the INI and HAL files for ``profile`` in ``workdir``."""
    if profile.dialect != "linuxcnc":
        raise CamtubeError(f"machine {profile.name!r} is a {profile.dialect} profile; the motion run needs a "
                           "linuxcnc profile (e.g. --machine linuxcnc-rotary)")
    w = Path(workdir)
    coords = _coordinates(profile)
    servo_ns = int(round(profile.servo_period_s * 1e9))
    rot = profile.axes[1] if profile.rotary else None
    lin = [profile.axis(a) for a in profile.axes if a != rot]
    lin_v = max(v.max_velocity for v in lin)
    ini = [
        "[EMC]", "VERSION = 1.1", "MACHINE = camtube-motion", "DEBUG = 0",
        "[DISPLAY]", f"DISPLAY = {driver}",
        "[TASK]", "TASK = milltask", "CYCLE_TIME = 0.010",
        "[RS274NGC]", f"PARAMETER_FILE = {w / 'sim.var'}",
        "[EMCMOT]", "EMCMOT = motmod", "COMM_TIMEOUT = 100000", f"SERVO_PERIOD = {servo_ns}",
        "[EMCIO]", "EMCIO = io", "CYCLE_TIME = 0.100", f"TOOL_TABLE = {w / 'tool.tbl'}",
        "[HAL]", f"HALFILE = {w / 'camtube.hal'}",
        "[TRAJ]", f"COORDINATES = {coords}", "LINEAR_UNITS = mm", "ANGULAR_UNITS = degree",
        f"DEFAULT_LINEAR_VELOCITY = {_ini_number(lin_v)}", f"MAX_LINEAR_VELOCITY = {_ini_number(lin_v)}",
        "NO_FORCE_HOMING = 1", f"POSITION_FILE = {w / 'position.txt'}",
    ]
    if rot:
        v = profile.axis(rot).max_velocity
        ini += [f"DEFAULT_ANGULAR_VELOCITY = {_ini_number(v)}", f"MAX_ANGULAR_VELOCITY = {_ini_number(v)}"]
    ini += ["[KINS]", f"JOINTS = {len(coords)}", f"KINEMATICS = trivkins coordinates={coords}"]
    for j, letter in enumerate(coords):
        lim = profile.axis(letter)
        angular = letter == rot
        span = 1e6 if angular else 1e4
        common = [f"MIN_LIMIT = {_ini_number(-span)}", f"MAX_LIMIT = {_ini_number(span)}",
                  f"MAX_VELOCITY = {_ini_number(lim.max_velocity)}",
                  f"MAX_ACCELERATION = {_ini_number(lim.max_acceleration)}"]
        ini += [f"[AXIS_{letter}]"] + common
        ini += [f"[JOINT_{j}]", f"TYPE = {'ANGULAR' if angular else 'LINEAR'}"] + common + [
            "FERROR = 1000", "MIN_FERROR = 1000", "HOME = 0", "HOME_OFFSET = 0", "HOME_SEARCH_VEL = 0",
            "HOME_LATCH_VEL = 0", "HOME_SEQUENCE = 0"]
    n_dio = max(4, (profile.gate_output or 0) + 1)
    outs = (profile.power_output, profile.frequency_output, profile.dose_output, profile.radius_output)
    n_aio = max(4, max((o for o in outs if o is not None), default=0) + 1)
    dose = profile.gating == "distance"
    hal = [
        "loadrt [KINS]KINEMATICS",
        f"loadrt [EMCMOT]EMCMOT servo_period_nsec=[EMCMOT]SERVO_PERIOD num_joints=[KINS]JOINTS "
        f"num_dio={n_dio} num_aio={n_aio}",
        f"loadrt sampler depth=200000 cfg={'fffbf' if dose else 'fffb'}",
        "addf motion-command-handler servo-thread",
        "addf motion-controller servo-thread",
    ]
    dose_lines = dose_hal(profile) if dose else []
    hal += [ln for ln in dose_lines if ln.startswith(("loadrt", "addf"))]
    hal += ["addf sampler.0 servo-thread"]
    hal += [f"net j{j} joint.{j}.motor-pos-cmd => joint.{j}.motor-pos-fb" for j in range(len(coords))]
    hal += [
        "net estop-loop iocontrol.0.user-enable-out iocontrol.0.emc-enable-in",
        "net tool-prep-loop iocontrol.0.tool-prepare iocontrol.0.tool-prepared",
        "net tool-change-loop iocontrol.0.tool-change iocontrol.0.tool-changed",
    ]
    hal += [f"net rec-{a.lower()} axis.{a.lower()}.pos-cmd => sampler.0.pin.{k}" for k, a in enumerate(profile.axes)]
    hal += [f"net rec-gate motion.digital-out-{profile.gate_output:02d} => sampler.0.pin.3",
            "setp sampler.0.enable 0"]
    hal += [ln for ln in dose_lines if not ln.startswith(("loadrt", "addf"))]
    if dose:
        hal += ["net laser-rate-khz => sampler.0.pin.4"]
    return {"camtube.ini": "\n".join(ini) + "\n", "camtube.hal": "\n".join(hal) + "\n", "tool.tbl": "",
            "sim.var": ""}


def dose_hal(profile) -> list[str]:
    """HAL lines of distance gating: the pulses of each servo cycle follow the distance commanded in that cycle.

    A position-synchronised output fires by position: the pulses of a servo cycle are the path
    length the stage moves in it times the pulses per mm. LinuxCNC's motion controller writes, in
    one servo cycle, the commanded position ``p_k`` and the motion-synchronised outputs (from rest
    the gate opens in the cycle of a cut's first step and closes in the cycle of the next move's
    first step); the stage moves from ``p_(k-1)`` to ``p_k`` while they are in force. So, with stock
    components only (as LinuxCNC's ``laserpower`` scales the power to the speed), run after
    ``motion-controller`` in the same thread: ``ddt`` turns each commanded axis position
    (``axis.L.pos-cmd``) into ``(p_k - p_(k-1)) / T``, the step of this cycle per second (no
    extrapolation: the step is known, not estimated); for a rotary axis ``mult2`` and ``scale``
    turn deg/s into surface mm/s (``x radius_output x pi/180``); ``hypot`` gives the path length
    of the step per second; ``mult2`` times the pulses per mm (analog output ``dose_output``) and
    the gate (``conv_bit_float``), ``scale`` x 0.001 gives kHz on the signal ``laser-rate-khz``
    (wire it to the laser's external pulse-rate or trigger input): rate x T is the pulses of the
    cycle, the step's length x the pulses per mm however the stage accelerates or stops.
    """
    ax, ac = profile.axes[0].lower(), profile.axes[1].lower()
    hal = ["loadrt ddt count=2", "loadrt mult2 count=3", "loadrt scale count=2", "loadrt hypot count=1",
           "loadrt conv_bit_float count=1"]
    for f in ("ddt.0", "ddt.1", "mult2.0", "scale.0", "hypot.0", "mult2.1", "conv-bit-float.0", "mult2.2",
              "scale.1"):
        hal.append(f"addf {f} servo-thread")
    hal += [
        f"net rec-{ax} ddt.0.in", f"net rec-{ac} ddt.1.in",  # the recorder's nets of axis.L.pos-cmd
        "net dose-v-ax ddt.0.out => hypot.0.in0",
    ]
    if profile.rotary:
        hal += ["net dose-v-c-deg ddt.1.out => mult2.0.in0",
                f"net dose-radius motion.analog-out-{profile.radius_output:02d} => mult2.0.in1",
                "net dose-v-c-rad mult2.0.out => scale.0.in", f"setp scale.0.gain {math.pi / 180.0!r}",
                "net dose-v-c scale.0.out => hypot.0.in1"]
    else:
        hal += ["net dose-v-c ddt.1.out => hypot.0.in1"]
    hal += [
        "net surface-speed hypot.0.out => mult2.1.in0",
        f"net dose-ppmm motion.analog-out-{profile.dose_output:02d} => mult2.1.in1",
        "net rec-gate conv-bit-float.0.in",
        "net dose-gate-f conv-bit-float.0.out => mult2.2.in1",
        "net dose-pps mult2.1.out => mult2.2.in0", "net dose-pps-gated mult2.2.out => scale.1.in",
        "setp scale.1.gain 0.001", "net laser-rate-khz scale.1.out",
    ]
    return hal


def controller_error(program: str, errors: list) -> str:
    """The line that says what LinuxCNC's controller reported running ``program`` (its errors, or none: the sampler's
    FIFO overflowed), with the line of the program it names and the fix (the message had neither)."""
    if not errors:
        return (f"{program}: the controller reported: the sampler FIFO overflowed (samples lost); fix: run it again "
                "on a quieter machine (the recorder runs in real time)")
    text = "; ".join(" ".join(str(e).split()) for e in errors)
    if "timed out waiting for" in text or "stalled for" in text:   # the driver's own watch, not the program
        return (f"{program}: the controller reported: {text}; fix: run it again on a quieter machine (LinuxCNC runs "
                "in real time)")
    m = re.search(r"\bline (\d+)", text, re.IGNORECASE)
    at = f" at line {m.group(1)}" if m else ""
    return (f"{program}: the controller reported: {text}; fix: correct the program{at} (a program camtube toolpath "
            "wrote runs as written: write it again if it was edited)")


#: A word's letter followed by no value (a number, an expression ``[..]`` or a parameter ``#n``): ``X=abc``, ``F``.
_WORD_WITHOUT_NUMBER = re.compile(r"(?<![A-Z])([A-Z])\s*(?![-+\d.\[#\s])(?=\S|$)")
#: A line of LinuxCNC's O-word flow control (its keywords are letters without numbers): not checked word by word.
_FLOW = re.compile(r"(^|\s)O\s*(\d|<)|\b(SUB|ENDSUB|CALL|IF|ELSEIF|ELSE|ENDIF|WHILE|ENDWHILE|DO|REPEAT|ENDREPEAT|RETURN|"
                   r"BREAK|CONTINUE)\b")
_AXIS_WORD = re.compile(r"(?<![A-Z])([XYZABCUVW])\s*[-+]?(?:\d+\.?\d*|\.\d+)")
_HEADER_MACHINE = re.compile(r"on machine ([\w.-]+)")


def check_program(path: str | os.PathLike, profile) -> str:
    """The text of a program ``profile`` can run, or :class:`MotionRunError` with one line saying why not.

    Read before LinuxCNC starts (a wrong file used to cost a 12 s timeout or a traceback):
    refuses binary data, a YAML file (a pattern or profile given by mistake), a program with no
    G0/G1 moves, and one that moves axes the profile does not have (a flat-bed GRBL ``.nc``, or a
    program written for another machine: the message names the machine its header gives).
    """
    path = Path(path)
    try:
        raw = read_input_bytes(path)
    except OSError as exc:
        raise MotionRunError(f"{path}: cannot read the program: {exc.strerror}") from None
    fix = "give the .ngc that `camtube toolpath` wrote for a LinuxCNC machine"
    bad = raw.find(b"\x00")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        bad = exc.start if bad < 0 else min(bad, exc.start)
    if bad >= 0:
        raise MotionRunError(f"{path}: not a G-code program (binary data at byte {bad}); {fix}")
    raw_lines = text.splitlines()
    lines = [ln.split(";", 1)[0] for ln in raw_lines]
    # each line's words: (comments) first (camtube's header comments hold ';'), then a ';' comment, then a '(' left
    # open to the line's end
    body = [re.sub(r"\([^)]*\)", "", ln).split(";", 1)[0].split("(", 1)[0].strip().upper() for ln in raw_lines]
    moves = [ln for ln in body if re.match(r"^(N\d+\s*)?G0?[01](?!\d)", ln)]
    if path.suffix.lower() in (".yaml", ".yml") or (not moves and any(re.match(r"^[a-z_]+:", ln) for ln in lines)):
        raise MotionRunError(f"{path}: a YAML file, not a G-code program; run `camtube toolpath {path.name} -o DIR` "
                             f"and give DIR/NAME.ngc")
    if not moves:
        raise MotionRunError(f"{path}: no G0/G1 moves: not a G-code program camtube wrote; {fix}")
    for k, ln in enumerate(body):
        # a word whose letter has no number (X=abc): the controller said only "bad number format ... parsing ''",
        # naming no line, after a real-time start
        w = None if _FLOW.search(ln) else _WORD_WITHOUT_NUMBER.search(ln)
        if w:
            raise MotionRunError(f"{path}:{k + 1}: the word {w.group(1)} has no number ({raw_lines[k].strip()!r}); fix: "
                                 f"correct that line (a program camtube toolpath wrote runs as written: write it again "
                                 "if it was edited)")
    used = sorted({m for ln in moves for m in _AXIS_WORD.findall(ln)})
    foreign = [a for a in used if a not in profile.axes]
    if foreign:
        m = _HEADER_MACHINE.search(text[:2000])
        whose = (f"it was written for machine {m.group(1)}: give --machine {m.group(1)}" if m and m.group(1) !=
                 profile.name else f"give --machine NAME for the machine it was written for (`camtube machines`)")
        if "M5" in body and "G93" not in body:  # a GRBL flat-bed program (G94, spindle-gated)
            whose = "a flat-bed GRBL program (.nc) cannot run on LinuxCNC's motion controller; " + fix
        raise MotionRunError(f"{path}: moves axis {', '.join(foreign)}, which machine {profile.name} does not have "
                             f"(axes {' '.join(profile.axes)}); {whose}")
    return text


def split_program(text: str, max_moves: int = PIECE_MOVES) -> list[str]:
    """A camtube program as consecutive programs of whole passes, each at most ``max_moves`` moves.

    Every piece repeats the modal preamble (units, blending, feed mode, gate off; not the
    preamble's moves) and ends with ``M2``; the last keeps the original postamble. The machine
    is at rest with the gate closed between passes, so running the pieces one after the other
    moves it exactly as the whole program does. A pass entered by a beam-on link (its first
    line a ``G1``: chained passes) continues the run of the one before and is never the first
    of a piece.
    """
    lines = text.splitlines()
    starts = [i for i, ln in enumerate(lines) if ln.startswith(("(pass ", "; pass "))
              and not (i + 1 < len(lines) and lines[i + 1].startswith("G1 "))]
    if not starts:
        return [text]
    head = lines[:starts[0]]
    modal = [ln for ln in head if ln.strip() and not ln.startswith(("(", ";", "G0 "))]
    end = max(i for i, ln in enumerate(lines) if ln.startswith(("G0 ", "G1 "))) + 1
    while end < len(lines) and not lines[end].startswith(("M2", "M30")) and lines[end].startswith(("M63", "M5 ")):
        end += 1
    tail = lines[end:]
    bounds = starts + [end]
    pieces, cur, moves = [], [], 0
    for a, b in zip(bounds[:-1], bounds[1:]):
        block = lines[a:b]
        n = sum(1 for ln in block if ln.startswith(("G0 ", "G1 ")))
        if cur and moves + n > max_moves:
            pieces.append(cur)
            cur, moves = [], 0
        cur = cur + block
        moves += n
    pieces.append(cur)
    out = []
    for k, body in enumerate(pieces):
        pre = head if k == 0 else modal
        # a piece ends with the next pass's rapid: its last move is then no lead-out the controller would
        # brake early for (the next piece repeats that rapid, a move of length 0)
        nxt = [ln for ln in pieces[k + 1] if ln.startswith("G0 ")][:1] if k < len(pieces) - 1 else []
        post = tail if k == len(pieces) - 1 else nxt + [ln for ln in modal if ln.startswith("M65")] + ["M2"]
        out.append("\n".join(pre + body + post) + "\n")
    return out


def run_program(ngc: str | os.PathLike, profile, *, timeout_s: float = 3600.0, keep_every_s: float = 0.0005,
                workdir: str | os.PathLike | None = None, piece_moves: int = PIECE_MOVES) -> Recording:
    """Run ``ngc`` on LinuxCNC's motion controller with ``profile``'s limits; return the recording.

    Parameters
    ----------
    ngc : path
        The program (LinuxCNC dialect).
    profile : MachineProfile
        A ``linuxcnc`` profile: axes, limits, servo period, gate output.
    timeout_s : float
        Real-time limit of the run (s).
    keep_every_s : float
        Where the motion is straight at constant speed and the gate steady, keep one
        cycle in this many seconds (the others lie on the line between).
    workdir : path, optional
        Keep the configuration, log and recording here (default: a temporary folder, removed).
    piece_moves : int
        Run the program in pieces of at most this many moves (:func:`split_program`).

    Raises
    ------
    MotionUnavailable
        LinuxCNC is not installed.
    MotionRunError
        The controller reported errors (limits, unknown codes) or the run did not finish.
    """
    why = unavailable_reason()
    if why:
        raise MotionUnavailable(why)
    ngc = Path(ngc).resolve()
    if not ngc.is_file():
        raise MotionRunError(f"{ngc}: no such program")
    tmp = None
    if workdir is None:
        tmp = tempfile.TemporaryDirectory(prefix="camtube-motion-")
        work = Path(tmp.name)
    else:
        work = Path(workdir).resolve()
        work.mkdir(parents=True, exist_ok=True)
    try:
        with _machine_lock():
            return _run(ngc, profile, work, timeout_s, keep_every_s, piece_moves)
    finally:
        if tmp is not None:
            tmp.cleanup()


@contextlib.contextmanager
def _machine_lock():
    """One LinuxCNC at a time on this computer (HAL and RTAPI use fixed shared-memory keys): wait for the lock."""
    import fcntl

    with open(os.path.join(tempfile.gettempdir(), "camtube-linuxcnc.lock"), "a+") as fh:
        fcntl.flock(fh, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(fh, fcntl.LOCK_UN)


def _run(ngc: Path, profile, work: Path, timeout_s: float, keep_every_s: float, piece_moves: int) -> Recording:
    driver = work / "driver.py"
    shutil.copyfile(Path(__file__).with_name("_driver.py"), driver)
    driver.chmod(0o755)
    for name, text in config_texts(profile, work, str(driver)).items():
        (work / name).write_text(text)
    (work / "position.txt").unlink(missing_ok=True)
    samples, status_file = work / "samples.txt", work / "status.json"
    env = dict(os.environ)
    pieces = split_program(ngc.read_text(encoding="utf-8"), piece_moves)
    paths = []
    for k, text in enumerate(pieces):
        pth = work / f"piece{k:04d}.ngc"
        pth.write_text(text)
        paths.append(str(pth))
    env.update(CAMTUBE_NGC=os.pathsep.join(paths), CAMTUBE_SAMPLES=str(samples), CAMTUBE_STATUS=str(status_file),
               CAMTUBE_KEEP_EVERY=str(max(1, round(keep_every_s / profile.servo_period_s))),
               CAMTUBE_TIMEOUT_S=str(timeout_s))
    env.pop("PYTHONPATH", None)  # the driver runs in LinuxCNC's Python, not ours
    if os.geteuid() == 0:  # rtapi_app refuses root: run it as nobody with a FIFO that user can write
        fifo = work / "fifo"
        fifo.mkdir(exist_ok=True)
        fifo.chmod(0o777)
        work.chmod(0o755)
        env.update(RTAPI_UID="65534", RTAPI_FIFO_PATH=str(fifo / "rtapi_fifo"))
    log = work / "linuxcnc.log"
    with open(log, "w") as lf:
        try:
            # a shared computer: raise the priority of the controller's threads (root only; POSIX non-realtime)
            nice = ["nice", "-n", "-15"] if os.geteuid() == 0 and shutil.which("nice") else []
            proc = subprocess.run(nice + ["linuxcnc", "-r", str(work / "camtube.ini")], cwd=work, env=env, stdout=lf,
                                  stderr=subprocess.STDOUT, timeout=timeout_s + 60)
        except subprocess.TimeoutExpired:
            raise MotionRunError(f"LinuxCNC did not finish within {timeout_s + 60:g} s (log: {log})") from None
    try:
        status = json.loads(status_file.read_text())
    except (OSError, ValueError):
        tail = log.read_text(errors="replace").strip().splitlines()[-5:]
        raise MotionRunError(f"LinuxCNC did not run the driver (exit {proc.returncode}): " + " | ".join(tail)
                             ) from None
    if status["errors"] or status["overrun"]:
        raise MotionRunError(controller_error(ngc.name, status["errors"]))
    data = np.fromstring(samples.read_text(), sep=" ")  # noqa: NPY201 (fast text parse)
    data = data.reshape(-1, 6 if profile.gating == "distance" else 5)
    return Recording(data[:, 0].astype(np.int64), data[:, 1], data[:, 2], data[:, 3], data[:, 4] > 0.5,
                     float(profile.servo_period_s), float(status["wall_s"]),
                     data[:, 5] if data.shape[1] > 5 else None)
