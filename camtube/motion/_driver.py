#!/usr/bin/python3
"""LinuxCNC "display" that runs one program headless and records it (run by ``linuxcnc -r``, not imported).

It runs under LinuxCNC's own Python (the ``linuxcnc`` module), uses only the
standard library, and is configured by environment variables set by
:func:`camtube.motion.linuxcnc.run_program`:

``CAMTUBE_NGC``        program(s) to run one after the other (separated by ``os.pathsep``);
``CAMTUBE_SAMPLES``    output: one line per kept servo cycle, ``index x y z gate`` (axis.*.pos-cmd);
``CAMTUBE_STATUS``     output: JSON with the outcome (errors of the controller, overruns);
``CAMTUBE_KEEP_EVERY`` keep every n-th cycle where nothing changes direction or gate;
``CAMTUBE_TIMEOUT_S``  give up after this many seconds of real time.

Steps: estop reset, machine on, home all joints (zero search velocities: homing
is immediate), auto mode, open, start ``halsampler``, enable the sampler, run,
poll until the interpreter is idle and the motion queue empty, disable the
sampler, stop ``halsampler``. A cycle is kept when the gate changes within two
cycles of it, when the motion changes direction or speed, or every n-th cycle:
the dropped ones lie on straight lines at constant speed between kept ones.
"""
import json
import os
import subprocess
import sys
import threading
import time

import linuxcnc

STALL_S = 30.0  # no motion for this long while the program is not done: the planner is stuck


def main() -> int:
    ngc = os.environ["CAMTUBE_NGC"]
    out_path = os.environ["CAMTUBE_SAMPLES"]
    status_path = os.environ["CAMTUBE_STATUS"]
    keep_every = max(1, int(os.environ.get("CAMTUBE_KEEP_EVERY", "1")))
    timeout_s = float(os.environ.get("CAMTUBE_TIMEOUT_S", "3600"))
    status = {"ok": False, "errors": [], "overrun": False, "samples": 0, "wall_s": None}
    s = linuxcnc.stat()
    c = linuxcnc.command()
    e = linuxcnc.error_channel()

    def errors():
        while True:
            m = e.poll()
            if not m:
                return
            status["errors"].append(str(m[1]).strip())

    def wait(cond, limit, what, every=0.05):
        t0 = time.time()
        while time.time() - t0 < limit:
            s.poll()
            if cond():
                return
            time.sleep(every)
        raise RuntimeError(f"timed out waiting for {what}")

    sampler = None
    try:
        c.state(linuxcnc.STATE_ESTOP_RESET)
        wait(lambda: s.task_state == linuxcnc.STATE_ESTOP_RESET, 60, "estop reset")
        c.state(linuxcnc.STATE_ON)
        wait(lambda: s.task_state == linuxcnc.STATE_ON, 60, "machine on")
        c.mode(linuxcnc.MODE_MANUAL)
        c.wait_complete()
        c.home(-1)
        c.wait_complete()
        wait(lambda: all(s.homed[i] for i in range(s.joints)), 90, "homing")
        c.mode(linuxcnc.MODE_AUTO)
        c.wait_complete()
        c.program_open(ngc.split(os.pathsep)[0])
        c.wait_complete()
        errors()
        sampler = subprocess.Popen(["halsampler", "-t"], stdout=subprocess.PIPE, text=True, bufsize=1 << 20)
        kept = [0]
        cycle, pos = [0], [None]

        def reader():
            # window of three cycles: keep the middle one if the gate changes next to it, the motion
            # turns or changes speed there, or on the n-th cycle
            with open(out_path, "w") as out:
                w = []
                last_i = None
                for line in sampler.stdout:
                    f = line.split()
                    if len(f) < 5:
                        continue
                    i = int(f[0])
                    if last_i is not None and i != last_i + 1:
                        status["overrun"] = True
                    last_i = i
                    w.append((i, float(f[1]), float(f[2]), float(f[3]), f[4], line))
                    cycle[0] = i
                    if (f[1], f[2], f[3]) != pos[0]:
                        pos[0] = (f[1], f[2], f[3])
                    if len(w) < 3:
                        if len(w) == 1:
                            out.write(line)
                            kept[0] += 1
                        continue
                    a, b, cc = w[-3], w[-2], w[-1]
                    keep = (b[4] != a[4] or b[4] != cc[4] or b[0] % keep_every == 0
                            or any(abs((cc[k] - b[k]) - (b[k] - a[k])) > 5e-6 for k in (1, 2, 3)))
                    if keep:
                        out.write(b[5])
                        kept[0] += 1
                    w = w[-2:]
                if w:
                    out.write(w[-1][5])
                    kept[0] += 1

        t = threading.Thread(target=reader, daemon=True)
        t.start()
        last = {"key": None, "t": time.time()}

        def finished():
            if s.interp_state == linuxcnc.INTERP_IDLE and s.queue == 0 and s.inpos:
                return True
            # watch the recorded stream (the task's status can lag): no motion for STALL_S
            if pos[0] != last["key"]:
                last["key"], last["t"] = pos[0], time.time()
            elif time.time() - last["t"] > STALL_S:
                raise RuntimeError(f"the controller stalled for {STALL_S:g} s at servo cycle {cycle[0]}, "
                                   f"recorded position {pos[0]}, program line {s.motion_line}, queue {s.queue}, "
                                   f"interp {s.interp_state}, exec {s.exec_state}")
            return False

        t0 = time.time()
        for k, piece in enumerate(ngc.split(os.pathsep)):
            if k:
                c.program_open(piece)
                c.wait_complete()
                errors()
            subprocess.run(["halcmd", "setp", "sampler.0.enable", "1"], check=True)
            c.auto(linuxcnc.AUTO_RUN, 0)
            # polled every ms: a short piece on a fast stage (the last of a chained drawing on air bearings) may begin
            # and end within the 50 ms the other waits poll at, and was once taken as never started (a CI run)
            wait(lambda: s.interp_state != linuxcnc.INTERP_IDLE or s.queue > 0, 10, "the program to start", 0.001)
            last["key"], last["t"] = None, time.time()
            wait(finished, timeout_s, "the program to finish")
            time.sleep(0.02)
            subprocess.run(["halcmd", "setp", "sampler.0.enable", "0"], check=True)
            if status["errors"]:
                break
        status["wall_s"] = time.time() - t0
        time.sleep(0.3)
        sampler.terminate()
        t.join(30)
        status["samples"] = kept[0]
        errors()
        status["ok"] = not status["errors"] and not status["overrun"]
    except Exception as exc:  # the driver must report any failure to the runner, then exit
        status["errors"].append(f"{type(exc).__name__}: {exc}")
        errors()
    finally:
        if sampler is not None and sampler.poll() is None:
            sampler.kill()
        with open(status_path, "w") as f:
            json.dump(status, f)
    return 0 if status["ok"] else 1


if __name__ == "__main__":
    sys.exit(main())
