"""Run the shipped presets on LinuxCNC's motion controller (real time: about an hour) and print the table.

    python scripts/run_motion.py                                  # both LinuxCNC profiles, every preset
    python scripts/run_motion.py --machine linuxcnc-surface --preset tube1
    python scripts/run_motion.py --table out/motion.jsonl         # print the table of earlier results

For each (machine, preset): plan the preset, write its G-code for the machine and the job file,
estimate the time from the G-code (``camtube.machine.motion_time``), run it with ``camtube.motion``
and measure the recording against the job. One JSON line per run is appended to ``--out`` as soon
as it finishes; the markdown table (the one in docs/motion.md) is printed at the end.
"""
from __future__ import annotations

import argparse
import json
import shutil
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

PRESETS = ("tube1", "tube2", "tube3", "tube1-bidirectional")
#: The curved drawings of issue 21 (examples/curved, outer radius 0.8 mm).
DRAWINGS = ("filleted", "slotted", "elliptical")
CURVED_RO_MM = 0.8
MACHINES = ("linuxcnc-surface", "linuxcnc-rotary")
#: The sort order of the table's machines.
MACHINE_ORDER = ("linuxcnc-rotary", "linuxcnc-surface", "linuxcnc-path", "linuxcnc-path-airbearing")


def load_job(preset: str, overrides=(), ordering: str = "interleaved"):
    """The planned job of a preset (``tube1``) or of a curved drawing (``filleted``), with ``--set`` overrides,
    in ``ordering`` (a run uses its machine profile's, ``profile.ordering``)."""
    from camtube.design.source import DrawingOptions, load_source
    from camtube.plan import plan_job

    if preset in DRAWINGS:
        loaded = load_source(ROOT / "examples" / "curved" / f"{preset}.dxf", overrides,
                             DrawingOptions(outer_radius_mm=CURVED_RO_MM))
    else:
        loaded = load_source(ROOT / "patterns" / f"{preset}.yaml", overrides)
    return plan_job(loaded.pattern, ordering=ordering)


def run_one(machine: str, preset: str, workdir=None, overrides=()) -> dict:
    from camtube.export.dialects import dialect_from_profile
    from camtube.machine import load_profile
    from camtube.machine.bound import time_optimal_s
    from camtube.motion.analysis import JobGeometry, analyse
    from camtube.motion.linuxcnc import run_program
    from camtube.machine.motion_time import estimate_program
    from camtube.export.outputs import toolpath_streams
    from camtube.io import write_set

    profile = load_profile(machine)
    dialect = dialect_from_profile(profile)
    job = load_job(preset, overrides, profile.ordering)
    bound = time_optimal_s(job, profile)
    with tempfile.TemporaryDirectory(prefix="camtube-run-motion-") as tmp:
        streams = toolpath_streams(job, (dialect,))
        keep = {k: v for k, v in streams.items() if k.endswith((dialect.suffix, ".job.json"))}
        write_set(tmp, keep)
        ngc = Path(tmp) / f"{job.name}{dialect.suffix}"
        est = estimate_program(ngc.read_text(), profile)
        rec = run_program(ngc, profile, timeout_s=4 * est.total_s + 120, workdir=workdir)
        rep = analyse(rec, JobGeometry.from_job_file(Path(tmp) / f"{job.name}.job.json"), profile,
                      estimate_s=est.total_s)
    d = rep.as_dict()
    d["preset"] = preset + "".join(f" {o}" for o in overrides)
    d["optimal_s"] = bound
    d["ordering"] = job.ordering
    return d


def rescore(r: dict) -> dict:
    """A result with its estimate (from the program written again) and time-optimal bound recomputed."""
    from camtube.export.dialects import dialect_from_profile
    from camtube.export.gcode import gcode
    from camtube.machine import load_profile
    from camtube.machine.bound import time_optimal_s
    from camtube.machine.motion_time import estimate_program

    name, *overrides = r["preset"].split()
    profile = load_profile(r["machine"])
    job = load_job(name, tuple(overrides), r.get("ordering", "interleaved"))  # rows before issue 21's chaining
    est = estimate_program(gcode(job, dialect_from_profile(profile)), profile).total_s
    return dict(r, estimate_s=est, estimate_error=est / r["run_time_s"] - 1.0, optimal_s=time_optimal_s(job, profile))


def _um(mm) -> str:
    """mm as um with 3 decimals; a dash where the figure was not measured (a run made before it existed)."""
    return "–" if mm is None or mm != mm else f"{1000 * mm:.3f}"


def table(rows: list[dict]) -> str:
    head = ("| machine | job | LinuxCNC run s | estimate s (error) | lower bound s | run / lower bound | "
            "time-optimal s | run / time-optimal | beam-on path vs cut length | dose within +-5 % | "
            "within +-5 % of scan speed | beam on outside regions um | corner missed by um | own pass: path / "
            "vertices um |")
    out = [head, "|" + "---|" * 14]
    for r in rows:
        opt = r.get("optimal_s", float("nan"))
        dose = r.get("dose_share", float("nan"))
        # the own-pass figures come as a pair; a run made before them has neither
        own = (f"{_um(r['max_path_dev_mm'])} / {_um(r['max_vertex_miss_mm'])}" if "max_vertex_miss_mm" in r
               else "– / –")
        # chained passes: the links are beam-on path beyond the cut length, stated beside it
        link = r.get("link_length_mm", 0.0)
        beam = f"{100 * r['length_error']:+.3f} %" + (
            f" (links {link:.2f} mm; {100 * r['path_length_error']:+.3f} % of cut + links)" if link > 0 else "")
        order = r.get("ordering", "interleaved")
        job = r["preset"] + ("" if order == "interleaved" else f" ({order})")
        out.append(f"| {r['machine']} | {job} | {r['run_time_s']:.2f} | {r['estimate_s']:.2f} "
                   f"({100 * r['estimate_error']:+.2f} %) | {r['lower_bound_s']:.2f} | "
                   f"{r['run_time_s'] / r['lower_bound_s']:.3f} | {opt:.2f} | {r['run_time_s'] / opt:.3f} | "
                   f"{beam} | {100 * dose:.2f} % | "
                   f"{100 * r['speed_share']:.2f} % | {1000 * r['max_outside_mm']:.3f} | "
                   f"{1000 * r['max_corner_miss_mm']:.3f} | {own} |")
    return "\n".join(out)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--machine", action="append", help=f"profile(s) (default {', '.join(MACHINES)})")
    ap.add_argument("--preset", action="append",
                    help=f"preset(s) or curved drawing(s) (default {', '.join(PRESETS)}; drawings: "
                         f"{', '.join(DRAWINGS)})")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="override a pattern key for every job, e.g. process.repeats=1 (a short run)")
    ap.add_argument("--out", default="motion-results.jsonl", help="JSON lines file the results are appended to")
    ap.add_argument("--table", metavar="JSONL", help="only print the table of a results file")
    ap.add_argument("--rescore", action="store_true",
                    help="with --table: recompute each run's estimate and time-optimal bound with this code "
                         "(the program is written again: the same moves as the one that ran)")
    args = ap.parse_args()
    if args.table:
        rows = [json.loads(x) for x in Path(args.table).read_text().splitlines() if x.strip()]
        # a rerun replaces a run (per machine, job and ordering)
        last = {(r["machine"], r["preset"], r.get("ordering", "interleaved")): r for r in rows if "error" not in r}
        kinds = {name: k for k, name in enumerate(PRESETS + DRAWINGS)}
        mk = {m: k for k, m in enumerate(MACHINE_ORDER)}
        rows = sorted(last.values(), key=lambda r: (r["preset"].split()[0] in DRAWINGS, mk.get(r["machine"], 99),
                                                    r.get("ordering", "interleaved") != "interleaved",
                                                    kinds.get(r["preset"].split()[0], 99)))
        if args.rescore:
            rows = [rescore(r) for r in rows]
        print(table(rows))
        return 0
    from camtube.motion.linuxcnc import MotionRunError, unavailable_reason

    why = unavailable_reason()
    if why:
        print(why, file=sys.stderr)
        return 2
    rows = []
    for preset in args.preset or PRESETS:
        for machine in args.machine or MACHINES:
            t0 = time.time()
            work = Path(tempfile.mkdtemp(prefix=f"camtube-run-motion-{machine}-{preset}-"))
            try:
                r = run_one(machine, preset, work, tuple(args.set))
            except MotionRunError as exc:  # report the failed run, keep its log, go on with the next
                print(f"{machine} {preset}: FAILED ({exc}); configuration and log kept in {work}", flush=True)
                with open(args.out, "a") as fh:
                    fh.write(json.dumps({"machine": machine, "preset": preset, "error": str(exc)}) + "\n")
                continue
            shutil.rmtree(work, ignore_errors=True)
            rows.append(r)
            with open(args.out, "a") as fh:
                fh.write(json.dumps(r) + "\n")
            print(f"{machine} {preset}: run {r['run_time_s']:.2f} s, estimate {100 * r['estimate_error']:+.2f} %, "
                  f"lower bound {r['lower_bound_s']:.2f} s, time-optimal {r['optimal_s']:.2f} s, "
                  f"length {100 * r['length_error']:+.3f} %, dose {100 * r['dose_share']:.2f} %, "
                  f"speed share {100 * r['speed_share']:.2f} %, "
                  f"outside {1000 * r['max_outside_mm']:.3f} um, corner {1000 * r['max_corner_miss_mm']:.3f} um, "
                  f"own pass: path {1000 * r['max_path_dev_mm']:.3f} um, vertices {1000 * r['max_vertex_miss_mm']:.3f} um "
                  f"({time.time() - t0:.0f} s)", flush=True)
    print(table(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
