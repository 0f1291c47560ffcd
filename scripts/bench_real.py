"""Diagnosis of whole-bench files (issue 19): :mod:`camtube.model.sim.bench`, several mechanisms at once.

Each file: two samples, 25-100 Hz, about 60,000 rows, 50 cycles with dwells and rests, the first cycle
dwelling longer, tracker spikes, dropouts (nan), stamp jitter and repeated stamps; one mechanism dominant,
others present. In the batches of ``ROUGH`` the trackers vary as labs' do: dropouts written as nan, 0 or the
last reading, bursts of interference over several rows, noise through a filter. The file is written as CSV and read back as a user's would be (rows with a missing value
dropped and counted), the instruments are checked (spikes set aside, the angle's lag estimated and
corrected), then ``diagnose`` runs on the rows kept.

Run: ``python scripts/bench_diagnose.py --batch bench`` (the sets the method was tuned on) or
``--batch bench-heldout`` (drawn once the method was settled, from a seed not used before; see
docs/diagnose.md for when it was run); or ``python scripts/bench_real.py bench bench-heldout``.
Each prints, per file, what was recommended, the RMSE before/after against the true floor, the noise-floor
estimate against the truth, the lag, the rows set aside, and the seconds (instruments + diagnosis); then the
count right and the seconds per 60,000-row file.
"""
from __future__ import annotations

import tempfile
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
from benchutil import ROOT

from camtube.design.loader import load_pattern
from camtube.model.core.predict import model_for_pattern, pattern_values
from camtube.model.data import format_csv, read_measurements
from camtube.model.diagnose import diagnose
from camtube.model.diagnose.instruments import check_instruments, confirm_lag
from camtube.model.sim.bench import (
    Backbone, Clock, Drive, Guide, LoadCell, Protocol, SampleBench, Tendon, Tracker, simulate_bench,
)

TOES = {"toe", "toe_shape", "toe_soft"}
#: Mechanisms by family: the effects of the library that are the right answer (empty: none is; the answer is
#: nothing recommended, and what is left follows ``follows``).
FAMILIES = {
    "control": (set(), None),
    "toe": (TOES, None),
    "slack": ({"slack"}, None),
    "lost motion": ({"slack", "play", "play_held", "carriage_hold", "carriage_gap"}, None),  # the drive: a carriage its rail holds, or backlash
    "creep": ({"creep", "creep_load", "viscoelastic"}, None),  # a slow viscoelastic element and creep: known equivalents
    "backbone": ({"relaxation", "relaxation2"}, None),  # the backbone relaxing: one arm or two (its set: the baseline's rest_angle)
    "backbone3": ({"relaxation", "relaxation2"}, None),  # a backbone with three arms: the same family
    "zero drift": (set(), "time"),
    "tracker drift": (set(), "time"),  # the tracker's zero drifts: an instrument's, the library has no form for it
    "lag": (set(), None),
    "friction": ({"friction", "capstan"}, None),  # one family: friction at the guide
    "sharp friction": ({"friction", "capstan"}, None),  # the same, its sign switching within a row (Coulomb's step)
}


def protocol_for(rate_hz: float, rows: int = 60_000, n_cycles: int = 50) -> Protocol:
    """Cycle timing giving about ``rows`` rows over two samples at ``rate_hz``."""
    cycle_s = rows / 2.0 / rate_hz / n_cycles
    return Protocol(n_cycles=n_cycles, ramp_s=0.3 * cycle_s, dwell_s=0.2 * cycle_s, rest_s=0.2 * cycle_s,
                    first_dwell_s=0.2 * cycle_s)


def _mild(rng: np.random.Generator) -> SampleBench:
    """A bench with small secondary mechanisms on (as any real one has)."""
    return SampleBench(
        drive=Drive(backlash_mm=float(rng.uniform(0.0, 0.005)), rail_friction_N=0.05),
        guide=Guide(mu=float(rng.uniform(0.0, 0.002))),
        tendon=Tendon(crimp_mm=float(rng.uniform(0.0, 0.01)), creep_A_mm_per_s=float(rng.uniform(0, 1e-6))),
        backbone=Backbone(relax=((float(rng.uniform(0.02, 0.1)), 3.0),)),
        tracker=Tracker(noise_deg=float(rng.uniform(0.1, 0.25))),
    )


def dominant(kind: str, base: SampleBench, rng: np.random.Generator, strength: float = 1.0) -> SampleBench:
    """``base`` with ``kind`` made the dominant mechanism."""
    u = lambda lo, hi: float(rng.uniform(lo, hi)) * strength  # noqa: E731
    if kind == "toe":
        return replace(base, tendon=replace(base.tendon, crimp_mm=u(0.15, 0.4), crimp_shape=float(rng.uniform(1.5, 4))))
    if kind == "slack":
        return replace(base, tendon=replace(base.tendon, slack_mm=u(0.08, 0.2)))
    if kind == "lost motion":
        return replace(base, drive=Drive(backlash_mm=u(0.1, 0.25), rail_friction_N=float(rng.uniform(0.05, 0.2))))
    if kind == "creep":
        return replace(base, tendon=replace(base.tendon, creep_A_mm_per_s=u(2e-4, 6e-4), creep_n=2.0,
                                            creep_sat_mm=float(rng.uniform(0.05, 0.15))))
    if kind == "backbone":
        return replace(base, backbone=Backbone(relax=((u(0.2, 0.4), float(rng.uniform(1, 4))),
                                                      (u(0.1, 0.3), float(rng.uniform(15, 40)))),
                                               yield_nmm=float(rng.uniform(3, 6)), set_rate_per_s=u(0.02, 0.05)))
    if kind == "backbone3":  # three relaxing arms a decade apart (a spectrum, not the library's one or two), and a set
        return replace(base, backbone=Backbone(relax=((u(0.1, 0.25), float(rng.uniform(0.5, 1.5))),
                                                      (u(0.1, 0.2), float(rng.uniform(5.0, 12.0))),
                                                      (u(0.08, 0.15), float(rng.uniform(60.0, 150.0)))),
                                               yield_nmm=float(rng.uniform(3, 6)), set_rate_per_s=u(0.02, 0.05)))
    if kind == "zero drift":
        return replace(base, load_cell=LoadCell(drift_N_per_h=u(0.2, 0.5), walk_N_per_sqrt_h=0.05))
    if kind == "tracker drift":  # the EM tracker's zero drifts (warm-up of its field generator and sensor)
        return replace(base, tracker=replace(base.tracker, drift_deg_per_h=u(2.0, 6.0)))
    if kind == "lag":
        return replace(base, tracker=replace(base.tracker, lag_ms=u(25, 80)))
    if kind == "friction":
        return replace(base, guide=Guide(mu=u(0.1, 0.2)))
    if kind == "sharp friction":
        return replace(base, guide=Guide(mu=u(0.1, 0.2), slip_mm_s=1e-6))
    if kind == "control":  # the paper's physics: nothing else (the instruments' artefacts stay)
        return SampleBench(tracker=base.tracker)
    raise ValueError(kind)


def rough_instruments(b: SampleBench, rng: np.random.Generator) -> SampleBench:
    """``b`` with a tracker as varied as labs' are: its dropouts written as ``nan``, 0 or its last reading; 0-8
    bursts of interference of 2-8 rows; in half the files its noise through a 10-50 ms first-order filter."""
    filter_ms = float(rng.uniform(10.0, 50.0)) if rng.random() < 0.5 else 0.0
    return replace(b, tracker=replace(b.tracker, dropout=str(rng.choice(["nan", "zero", "hold"])),
                                      n_bursts=int(rng.integers(0, 9)), burst_rows=(2, 8), filter_ms=filter_ms))


#: The peak tension (N) the bench's tubes reach at the largest stroke (the 99.9th percentile of the force in the
#: controls of bench-heldout15 and bench-heldout16): the scale of a load cell's range in :func:`rougher_instruments`.
PEAK_TENSION_N = {"tube1": 3.05, "tube2": 3.85, "tube3": 8.99}   # (tube3: a control of 20,000 rows at 25 Hz)


def rougher_instruments(b: SampleBench, rng: np.random.Generator, tube: str, rate_hz: float) -> SampleBench:
    """:func:`rough_instruments`, with interference lasting 2 rows to 2 s, and in a third of the samples a load
    cell whose range ends at 75-95 % of the peak tension (it reads its limit while the tension goes on)."""
    b = rough_instruments(b, rng)
    b = replace(b, tracker=replace(b.tracker, burst_rows=(2, max(8, int(2.0 * rate_hz)))))
    if rng.random() < 1.0 / 3.0:
        b = replace(b, load_cell=replace(b.load_cell, range_N=float(rng.uniform(0.75, 0.95)) * PEAK_TENSION_N[tube]))
    return b


def untared(b: SampleBench, rng: np.random.Generator) -> SampleBench:
    """``b`` with, in half the samples, a load cell not zeroed before the test: it reads 0.2-2 N high or low at zero
    tension (:attr:`LoadCell.offset_N`)."""
    if rng.random() < 0.5:
        off = float(rng.uniform(0.2, 2.0)) * (1.0 if rng.random() < 0.5 else -1.0)
        b = replace(b, load_cell=replace(b.load_cell, offset_N=off))
    return b


def shaped_protocol(rate_hz: float, max_stroke_mm: float, rng: np.random.Generator) -> Protocol:
    """A record shape unlike :func:`protocol_for`'s: 20-80 cycles, 30,000-90,000 rows over two samples, ramps of
    15-40 % of a cycle, no dwell at the top in a quarter of the files (else 5-30 %), rests of 5-30 %, a first dwell
    of 0-2 cycles' dwells, a peak stroke of 60-100 % of the tube's largest (``max_stroke_mm``) in 70 % of the files."""
    n_cycles = int(rng.integers(20, 81))
    rows = float(rng.uniform(30_000, 90_000))
    ramp, rest = float(rng.uniform(0.15, 0.4)), float(rng.uniform(0.05, 0.3))
    dwell = 0.0 if rng.random() < 0.25 else float(rng.uniform(0.05, 0.3))
    first = float(rng.uniform(0.0, 2.0)) * dwell
    cycle_s = rows / 2.0 / rate_hz / n_cycles / (2 * ramp + dwell + rest)   # (the fractions: of a cycle's length)
    peak = max_stroke_mm if rng.random() < 0.3 else float(rng.uniform(0.6, 1.0)) * max_stroke_mm
    return Protocol(n_cycles=n_cycles, ramp_s=ramp * cycle_s, dwell_s=dwell * cycle_s, rest_s=rest * cycle_s,
                    first_dwell_s=first * cycle_s, peak_mm=peak)


def protocol_of(spec: tuple) -> Protocol:
    """The commanded motion of a batch's file ``spec``: its own record shape (a batch of :data:`SHAPED`) or
    :func:`protocol_for` its rate."""
    return spec[6] if len(spec) > 6 else protocol_for(spec[2])


def draw_batch(seed: int, kinds: list, rough: bool = False, rougher: bool = False, untared_cells: bool = False,
               shapes: bool = False) -> list:
    """``[(name, tube, rate_hz, (SampleBench, SampleBench), (kind1, kind2), sim_seed)]`` drawn from ``seed``;
    ``rough``: each tracker's artefacts drawn too (:func:`rough_instruments`, from ``seed + 1``: the mechanisms are
    those of the plain batch); ``rougher``: those and longer interference, a load cell's range
    (:func:`rougher_instruments`); ``shapes``: the three tubes, rates of 25-200 Hz and each file's own record shape
    (:func:`shaped_protocol`, from ``seed + 3``), the shape a seventh item of each file."""
    rng = np.random.default_rng(seed)
    rng_ins = np.random.default_rng(seed + 1)
    rng_zero = np.random.default_rng(seed + 2)
    rng_shape = np.random.default_rng(seed + 3)
    out = []
    for i, kind in enumerate(kinds):
        k1, k2 = kind if isinstance(kind, tuple) else (kind, kind)
        tube = str(rng.choice(["tube1", "tube2"]))
        rate = float(rng.choice([25.0, 40.0, 50.0, 100.0]))
        if shapes:
            tube = str(rng_shape.choice(["tube1", "tube2", "tube3"]))
            rate = float(rng_shape.choice([25.0, 50.0, 100.0, 200.0]))
        b1 = dominant(k1, _mild(rng), rng)
        b2 = dominant(k2, _mild(rng), rng, strength=float(rng.uniform(0.7, 1.3)))
        if rougher:
            b1, b2 = rougher_instruments(b1, rng_ins, tube, rate), rougher_instruments(b2, rng_ins, tube, rate)
        elif rough:
            b1, b2 = rough_instruments(b1, rng_ins), rough_instruments(b2, rng_ins)
        if untared_cells:   # (from a generator of its own: the rest of the batch as drawn without it)
            b1, b2 = untared(b1, rng_zero), untared(b2, rng_zero)
        if k1 == "lag" == k2:  # one tracker for both samples
            b2 = replace(b2, tracker=replace(b2.tracker, lag_ms=b1.tracker.lag_ms))
        name = k1 if k1 == k2 else f"{k1} / {k2}"
        out.append((name, tube, rate, (b1, b2), (k1, k2), seed * 100 + i)
                   + ((shaped_protocol(rate, load_pattern(ROOT / "patterns" / f"{tube}.yaml").rules.max_stroke_mm,
                                       rng_shape),) if shapes else ()))
    return out


TUNE_KINDS = ["control", "control", "toe", "slack", "lost motion", "creep", "backbone", "zero drift", "lag",
              ("toe", "creep"), "friction"]
#: The fresh held-out batch: drawn once the method was settled (commit after the search object), from a seed
#: not used before, with another pair of mechanisms in one file; run once, reported separately.
HELDOUT_KINDS = ["control", "control", "toe", "slack", "lost motion", "creep", "backbone", "zero drift", "lag",
                 ("slack", "toe"), "friction"]
#: A second fresh held-out batch: drawn once creep_load, effects in some samples only and the capped all-rows check
#: were settled (bench and bench-heldout had been looked at), from a seed not used before, with two pairs of
#: mechanisms the earlier batches lack; run once, reported separately.
HELDOUT2_KINDS = ["control", "control", "toe", "slack", "lost motion", "creep", "backbone", "zero drift", "lag",
                  ("creep", "toe"), ("slack", "creep"), "friction"]
#: A third fresh held-out batch: drawn once the last rule was settled (a per-sample version with unresolved copies
#: never replaces the shared one; bench-heldout2 had been looked at), from a seed not used before; run once.
HELDOUT3_KINDS = ["control", "control", "toe", "slack", "lost motion", "creep", "backbone", "zero drift", "lag",
                  ("toe", "slack"), ("creep", "slack"), "friction"]
#: The sixth fresh held-out batch (issue 19, after the guide's capstan law): friction at the guide beside a toe.
HELDOUT6_KINDS = ["control", "control", "toe", "slack", "lost motion", "creep", "backbone", "zero drift", "lag",
                  ("friction", "toe"), ("creep", "slack"), "friction"]
#: The seventh fresh held-out batch (issue 19, after `relaxation` and baseline stand-ins): a backbone beside a toe.
HELDOUT7_KINDS = ["control", "control", "toe", "slack", "lost motion", "creep", "backbone", "zero drift", "lag",
                  ("backbone", "toe"), ("creep", "slack"), "friction"]
#: The eighth fresh held-out batch (issue 19, after the hardstop's plateau check and the retry of an empty round): a
#: backbone beside a slack tendon, friction at the guide beside a creeping tendon.
HELDOUT8_KINDS = ["control", "control", "toe", "slack", "lost motion", "creep", "backbone", "zero drift", "lag",
                  ("slack", "backbone"), ("friction", "creep"), "friction"]
HELDOUT9_KINDS = ["control", "control", "toe", "slack", "lost motion", "creep", "backbone", "zero drift", "lag",
                  ("lost motion", "toe"), ("creep", "lost motion"), "friction"]
#: The files most batches from here on begin with; each adds its pairs, a guide's friction and (later) a tracker's
#: drift.
USUAL_KINDS = ["control", "control", "toe", "slack", "lost motion", "creep", "backbone", "backbone3", "zero drift",
               "lag"]
#: The tenth fresh held-out batch (issue 19, after `relaxation2` and the samples' effects combined by what they
#: explain): a backbone with three relaxing arms a decade apart (a form the library does not have: its laws have one
#: or two arms), and a backbone beside a creeping tendon (the joint's relaxation against the tendon's creep).
HELDOUT10_KINDS = USUAL_KINDS + [("backbone", "creep"), "friction"]
#: The eleventh fresh held-out batch (issue 19, after the load cell's zero read at the rests, carriage_gap and the
#: joint's resting effects refused where the force at rest stays): the pairs the last changes were tuned on, drawn
#: anew, and a tracker whose zero drifts (an instrument's artefact the library has no form for).
HELDOUT11_KINDS = ["control", "control", "toe", "slack", "lost motion", "creep", "backbone", "zero drift", "lag",
                   ("toe", "slack"), ("creep", "slack"), ("creep", "lost motion"), "friction", "tracker drift"]
#: The twelfth fresh held-out batch (issue 19, after the carriage's slip held again, the resting effects beside the
#: drive and the zero's step test): lost motion alone twice, beside a toe and beside a creeping tendon, a zero drift.
HELDOUT12_KINDS = ["control", "control", "toe", "slack", "lost motion", "lost motion", "creep", "backbone",
                   "zero drift", "lag", ("lost motion", "toe"), ("creep", "lost motion"), "friction", "tracker drift"]
#: The thirteenth fresh held-out batch (issue 19, after the compiled history laws and the rule that a sample whose
#: per-sample copies do nothing there does not show the effect): lost motion alone twice, beside a creeping tendon
#: and a toe (the other way round from the twelfth batch), the usual files around them.
HELDOUT13_KINDS = ["control", "control", "toe", "slack", "lost motion", "lost motion", "creep", "backbone",
                   "zero drift", "lag", ("lost motion", "creep"), ("toe", "lost motion"), "friction", "tracker drift"]
#: The fourteenth fresh held-out batch (issue 19, after the floor became the noise's root mean square): lost motion
#: twice, a three-arm backbone, and two pairs no batch had: friction at the guide beside a slack tendon, a relaxing
#: backbone beside lost motion in the drive.
HELDOUT14_KINDS = ["control", "control", "toe", "slack", "lost motion", "lost motion", "creep", "backbone", "backbone3",
                   "zero drift", "lag", ("friction", "slack"), ("backbone", "lost motion"), "friction", "tracker drift"]
#: The fifteenth fresh held-out batch (issue 19, after bursts, a frozen tracker and noise correlated from row to row):
#: the usual files and two pairs, every tracker's artefacts drawn as well (dropouts written as nan, 0 or the last
#: reading, bursts, a filter on its noise).
HELDOUT15_KINDS = USUAL_KINDS + [("toe", "creep"), ("slack", "lost motion"), "friction", "tracker drift"]
#: The sixteenth fresh held-out batch (issue 19, after a stand-in of the baseline's rest angle was credited with its
#: gain): lost motion three times, beside a relaxing backbone and beside a creeping tendon, the usual files around them,
#: every tracker's artefacts drawn too.
HELDOUT16_KINDS = ["control", "control", "toe", "slack", "lost motion", "lost motion", "lost motion", "creep",
                   "backbone", "zero drift", "lag", ("lost motion", "backbone"), ("creep", "lost motion"), "friction",
                   "tracker drift"]
#: The seventeenth fresh held-out batch (issue 19, after a tracker's zeros through a dwell, interference lasting
#: seconds and a load cell at the end of its range were set aside): the usual files and two pairs, with the
#: instruments of :func:`rougher_instruments`.
HELDOUT17_KINDS = ["control", "control", "toe", "slack", "lost motion", "lost motion", "creep", "backbone",
                   "zero drift", "lag", ("toe", "slack"), ("backbone", "creep"), "friction", "tracker drift"]
#: The eighteenth fresh held-out batch (issue 19, after two bursts one over the other were set aside, and a device
#: refused as an input): the usual files, a three-arm backbone, and two pairs no batch had: friction at the guide
#: beside lost motion in the drive, a slack tendon beside a relaxing backbone; the instruments of
#: :func:`rougher_instruments`.
HELDOUT18_KINDS = ["control", "control", "toe", "slack", "lost motion", "lost motion", "creep", "backbone", "backbone3",
                   "zero drift", "lag", ("friction", "lost motion"), ("slack", "backbone"), "tracker drift"]
#: The nineteenth fresh held-out batch (issue 19, after the jumps of a burst were paired within the noise, bench-heldout18
#: looked at): the usual files, a toe beside a creeping tendon, lost motion beside friction at the guide (the other way
#: round from bench-heldout18), with the instruments of :func:`rougher_instruments`.
HELDOUT19_KINDS = ["control", "control", "toe", "slack", "lost motion", "lost motion", "creep", "backbone", "zero drift",
                   "lag", ("toe", "creep"), ("lost motion", "friction"), "friction", "tracker drift"]
#: The twentieth fresh held-out batch (issue 19, after the drive's speed was read across the rows set aside and a
#: parameter the rows kept barely depend on was held; bench-heldout18 and 19 looked at): the usual files, friction at
#: the guide twice and beside a toe and a creeping tendon, with the instruments of :func:`rougher_instruments`.
HELDOUT20_KINDS = ["control", "control", "toe", "slack", "lost motion", "creep", "backbone", "zero drift", "lag",
                   "friction", "friction", ("friction", "toe"), ("creep", "friction"), "tracker drift"]
#: The twenty-first fresh held-out batch (issue 19, after an unresolved parameter was measured against what its effect
#: does; bench-heldout18 .. 20 looked at): the usual files, lost motion twice and beside friction, a toe beside creep,
#: friction beside a relaxing backbone, with the instruments of :func:`rougher_instruments`.
HELDOUT21_KINDS = ["control", "control", "toe", "slack", "lost motion", "lost motion", "creep", "backbone", "zero drift",
                   "lag", "friction", ("lost motion", "friction"), ("toe", "creep"), ("friction", "backbone")]
#: The twenty-second fresh held-out batch (issue 19, after a burst with a dropout in it, a parameter with an infinite
#: standard error and a law at its sharp limit; bench-heldout18 .. 21 looked at): the usual files, a backbone of three
#: arms, friction plain and switching within a row, a backbone beside friction, slack beside lost motion.
HELDOUT22_KINDS = ["control", "control", "toe", "slack", "lost motion", "creep", "backbone3", "zero drift", "lag",
                   "friction", "sharp friction", ("backbone", "friction"), ("slack", "lost motion"), "tracker drift"]
#: The twenty-third fresh held-out batch (issue 19, after the carriage that settles and a drive the chain may not drop
#: beside a taut tendon at rest; bench-heldout18 .. 22 looked at): every carriage settles (:data:`SETTLED`); the usual
#: files, lost motion twice, beside a toe and beside friction.
HELDOUT23_KINDS = ["control", "control", "toe", "slack", "lost motion", "lost motion", "creep", "backbone", "zero drift",
                   "lag", "friction", ("lost motion", "toe"), ("friction", "lost motion"), "tracker drift"]
#: The twenty-fourth fresh held-out batch (issue 19, after the union of the samples' chains holds a copy the rows barely
#: depend on; bench-heldout18 .. 23 looked at): every carriage settles; the usual files, and three of two samples that
#: differ: a toe beside lost motion, slack beside creep, lost motion beside a relaxing backbone.
HELDOUT24_KINDS = ["control", "control", "toe", "slack", "lost motion", "creep", "backbone", "zero drift", "lag",
                   "friction", ("toe", "lost motion"), ("slack", "creep"), ("lost motion", "backbone"), "tracker drift"]
#: The twenty-fifth fresh held-out batch (issue 19, after the search's remaining fits went one per core, a drop's refit
#: was capped and a burst with a smaller jump inside was paired; bench-heldout18 .. 24 looked at): every carriage
#: settles; a backbone with three arms, a guide that switches within a row, and three files of two samples that
#: differ: friction beside a relaxing backbone, creep beside lost motion, a toe beside slack.
HELDOUT25_KINDS = ["control", "control", "toe", "slack", "lost motion", "creep", "backbone3", "zero drift", "lag",
                   "sharp friction", ("friction", "backbone"), ("creep", "lost motion"), ("toe", "slack"),
                   "tracker drift"]
#: A tuning batch of guides whose friction switches within a row (Coulomb's step), alone and beside the other
#: mechanisms, with the instruments of ``ROUGHER``: drawn to tune the rows the load cell reads ahead of the stroke
#: (issue 19, after the twenty-fifth batch); looked at, not held out.
SHARP_KINDS = ["sharp friction", "sharp friction", "sharp friction", ("sharp friction", "toe"),
               ("sharp friction", "backbone"), ("lost motion", "sharp friction"), ("sharp friction", "creep"),
               ("slack", "sharp friction")]
#: The twenty-sixth fresh held-out batch (issue 19, after the rows whose force reads a switch the stroke has not
#: logged): guides that switch within a row alone and beside creep and a backbone, a toe beside lost motion.
HELDOUT26_KINDS = ["control", "control", "toe", "slack", "lost motion", "creep", "backbone3", "zero drift", "lag",
                   "sharp friction", ("sharp friction", "creep"), ("backbone", "sharp friction"),
                   ("toe", "lost motion"), "tracker drift"]
#: The twenty-seventh fresh held-out batch (issue 19, after a long burst's jumps were read on the rows kept and beside
#: the joint's own jump under a cell at its limit, and a lag the blocks disagree on was left unresolved): both
#: backbones, guides smooth and sharp beside a toe and a three-arm backbone, a lag beside creep.
HELDOUT27_KINDS = USUAL_KINDS + [("friction", "toe"), ("backbone3", "sharp friction"), ("lag", "creep"),
                                 "tracker drift"]
#: The twenty-eighth fresh held-out batch (issue 19, after the angle's lag was read per sample where the samples'
#: trackers lag differently): a lag in one sample beside a toe, and beside a backbone, in the other; a smooth guide
#: beside a relaxing backbone; the instruments of bench-heldout17 and every carriage settling.
HELDOUT28_KINDS = USUAL_KINDS + [("lag", "toe"), ("lag", "backbone"), ("friction", "backbone"), "tracker drift"]
#: The twenty-ninth fresh held-out batch (issue 19, after the samples' own lags a few errors apart were tested against
#: the current model): a lag in one sample beside slack, and beside lost motion, in the other; a guide that switches
#: within a row beside creep.
HELDOUT29_KINDS = USUAL_KINDS + [("lag", "slack"), ("lag", "lost motion"), ("sharp friction", "creep"),
                                 "tracker drift"]
#: The thirtieth fresh held-out batch (issue 19, after the noise floor's row spacing was tested per sample): a toe
#: beside creep, lost motion beside a relaxing backbone, a three-arm backbone beside slack.
HELDOUT30_KINDS = USUAL_KINDS + [("toe", "creep"), ("lost motion", "backbone"), ("backbone3", "slack"),
                                 "tracker drift"]
#: The thirty-first fresh held-out batch (issue 19, after a better model's reading from rows further apart replaced the
#: floor): creep beside slack, a relaxing backbone beside a toe, lost motion beside creep.
HELDOUT31_KINDS = USUAL_KINDS + [("creep", "slack"), ("backbone", "toe"), ("lost motion", "creep"), "tracker drift"]
#: The thirty-second fresh held-out batch (issue 19, after a swap's replacement took the place of the effect it
#: replaced): a toe beside a three-arm backbone, slack beside a smooth guide, creep beside a relaxing backbone.
HELDOUT32_KINDS = USUAL_KINDS + [("toe", "backbone3"), ("slack", "friction"), ("creep", "backbone"), "tracker drift"]
#: The thirty-third fresh held-out batch (issue 19, after the union of the samples' chains held a copy at its off
#: value): a toe beside a relaxing backbone, lost motion beside a three-arm backbone, slack beside creep.
HELDOUT33_KINDS = USUAL_KINDS + [("toe", "backbone"), ("lost motion", "backbone3"), ("slack", "creep"),
                                 "tracker drift"]
#: The thirty-fourth fresh held-out batch (issue 19, after a gain judged on the log scale too and a lag confirmed in
#: one sample tested in another): creep beside a three-arm backbone, a backbone beside slack, a toe beside lost motion.
HELDOUT34_KINDS = USUAL_KINDS + [("creep", "backbone3"), ("backbone", "slack"), ("toe", "lost motion"),
                                 "tracker drift"]
#: The thirty-fifth fresh held-out batch (issue 19, after an effect one sample refuses was fitted in the others): a
#: relaxing backbone beside lost motion, a smooth guide beside a three-arm backbone, creep beside a smooth guide.
HELDOUT35_KINDS = USUAL_KINDS + [("backbone", "lost motion"), ("friction", "backbone3"), ("creep", "friction"),
                                 "tracker drift"]
HELDOUT36_KINDS = USUAL_KINDS + [("creep", "toe"), ("backbone3", "lost motion"), ("slack", "backbone3"),
                                 "sharp friction", "tracker drift"]
HELDOUT37_KINDS = USUAL_KINDS + [("sharp friction", "lost motion"), ("backbone3", "toe"), ("friction", "creep"),
                                 "sharp friction", "tracker drift"]
HELDOUT38_KINDS = USUAL_KINDS + [("lost motion", "creep"), ("friction", "toe"), ("backbone", "slack"),
                                 "sharp friction", "tracker drift"]
#: The thirty-ninth fresh held-out batch (issue 19, after the measurement files' sign, unit and time checks; the
#: diagnosis itself as for bench-heldout38): slack beside a toe, a lag beside a three-arm backbone, a smooth guide
#: beside slack.
HELDOUT39_KINDS = USUAL_KINDS + [("slack", "toe"), ("lag", "backbone3"), ("friction", "slack"), "sharp friction",
                                 "tracker drift"]
#: The fortieth fresh held-out batch (issue 19, after a lag under a load cell at its limit is read against the stroke):
#: a lag beside a relaxing backbone, creep beside a toe, slack beside lost motion, a smooth guide alone.
HELDOUT40_KINDS = USUAL_KINDS + [("lag", "backbone"), ("creep", "toe"), ("slack", "lost motion"), "friction",
                                 "tracker drift"]
#: The forty-first fresh held-out batch (issue 19, after a load cell not zeroed is re-zeroed where the rests say so, and
#: a lag under a cell at its limit is read against the stroke): in half the samples a cell not zeroed before the test
#: (:data:`UNTARED`), three lag files, slack and a toe beside lost motion and creep.
HELDOUT41_KINDS = ["control", "control", "toe", "slack", "lost motion", "creep", "backbone", "zero drift", "lag", "lag",
                   ("lag", "creep"), ("slack", "lost motion"), ("toe", "creep"), "friction", "tracker drift"]
#: The forty-second fresh held-out batch (issue 19, after the cell's zero is read whole where the joint at rest is
#: nearly straight; bench-heldout41 looked at): cells not zeroed in half the samples, slack beside creep, lost motion
#: beside a toe, a backbone beside slack.
HELDOUT42_KINDS = USUAL_KINDS + [("slack", "creep"), ("lost motion", "toe"), ("backbone", "slack"), "friction",
                                 "tracker drift"]
#: The forty-third fresh held-out batch (issue 19, after the lag scan's regressions were solved by the normal equations;
#: bench-heldout40 .. 42 looked at): cells not zeroed in half the samples, a guide whose friction switches within a row,
#: a lag beside slack, friction beside creep, a three-arm backbone beside a toe.
HELDOUT43_KINDS = USUAL_KINDS + [("lag", "slack"), ("friction", "creep"), ("backbone3", "toe"), "sharp friction",
                                 "tracker drift"]
#: The forty-fourth fresh held-out batch (issue 19, after the cell's reading before the first pull was read as its zero;
#: bench-heldout43 looked at): cells not zeroed in half the samples, lost motion beside a backbone and beside creep, a toe
#: beside slack.
HELDOUT44_KINDS = USUAL_KINDS + [("lost motion", "backbone"), ("toe", "slack"), ("creep", "lost motion"), "friction",
                                 "tracker drift"]
#: The forty-fifth fresh held-out batch (issue 19, after a cell's rows at its limit were left out of the force's noise
#: scale and the reading before the first pull was read from 2 rows; bench-heldout44 looked at): cells not zeroed in
#: half the samples, slack beside a backbone, a lag beside a toe, creep beside friction.
HELDOUT45_KINDS = USUAL_KINDS + [("slack", "backbone"), ("lag", "toe"), ("creep", "friction"), "sharp friction",
                                 "tracker drift"]
#: The forty-sixth fresh held-out batch (issue 19, the final method of the session after bench-heldout45, measured
#: again on a seed not used before; every batch above looked at): cells not zeroed in half the samples, creep beside a
#: three-arm backbone, a lag beside friction, a toe beside slack.
HELDOUT46_KINDS = USUAL_KINDS + [("creep", "backbone3"), ("lag", "friction"), ("toe", "slack"), "sharp friction",
                                 "tracker drift"]
#: The forty-seventh fresh held-out batch (issue 19, after the union fitted without a minor copy it cannot resolve,
#: overlapping bursts read by the sum of their jumps and a slow drift named below the stop ratio; bench-heldout44 and
#: 46 looked at): cells not zeroed in half the samples, a backbone beside a toe, friction beside slack, lost motion
#: beside creep.
HELDOUT47_KINDS = USUAL_KINDS + [("backbone", "toe"), ("friction", "slack"), ("lost motion", "creep"),
                                 "sharp friction", "tracker drift"]
#: The forty-eighth fresh held-out batch (issue 19, the final method of the session after bench-heldout47, with
#: interference a record ends in read from the ramp's rest; every batch above looked at): cells not zeroed in half the
#: samples, creep beside a three-arm backbone, a lag beside slack, friction beside a toe.
HELDOUT48_KINDS = USUAL_KINDS + [("backbone3", "creep"), ("lag", "slack"), ("friction", "toe"), "sharp friction",
                                 "tracker drift"]
#: The forty-ninth fresh held-out batch (issue 19, after a small drift alike at rest and under load was named as the
#: tracker's; every batch above looked at): cells not zeroed in half the samples, a toe beside a three-arm backbone,
#: creep beside slack, a lag beside lost motion.
HELDOUT49_KINDS = USUAL_KINDS + [("toe", "backbone3"), ("creep", "slack"), ("lag", "lost motion"), "friction",
                                 "tracker drift"]
#: The fiftieth fresh held-out batch (issue 19, after the drive's history ran through the rows set aside for the
#: angle alone; every batch above looked at): cells not zeroed in half the samples, lost motion beside a toe, a backbone
#: beside creep, a lag beside a three-arm backbone.
HELDOUT50_KINDS = USUAL_KINDS + [("lost motion", "toe"), ("backbone", "creep"), ("lag", "backbone3"),
                                 "sharp friction", "tracker drift"]
#: The fifty-first fresh held-out batch (issue 19, the method settled at the end of the session after
#: bench-heldout50; every batch above looked at): cells not zeroed in half the samples, lost motion beside a backbone,
#: slack beside friction, a three-arm backbone beside a toe.
HELDOUT51_KINDS = USUAL_KINDS + [("lost motion", "backbone"), ("slack", "friction"), ("backbone3", "toe"),
                                 "sharp friction", "tracker drift"]
#: A fresh held-out batch of record shapes (issue 19, the method settled after bench-heldout50): every batch above
#: has 50 cycles of one shape, 60,000 rows at 25-100 Hz, tubes 1 and 2; here each file draws its tube among the three,
#: its rate (25-200 Hz), its cycles, rows, ramps, dwells (none in some), rests and peak stroke
#: (:func:`shaped_protocol`); the mechanisms and artefacts as bench-heldout51's.
SHAPES_KINDS = USUAL_KINDS + [("toe", "creep"), ("friction", "slack"), ("backbone", "lost motion"), "sharp friction",
                              "tracker drift"]
#: The fifty-second fresh held-out batch (issue 19, the method settled after bench-heldout51 and bench-shapes, both
#: looked at): record shapes drawn per file as bench-shapes' (the three tubes, 25-200 Hz), cells not zeroed in half the
#: samples, slack beside a three-arm backbone, a guide's friction beside lost motion, a toe beside slack.
HELDOUT52_KINDS = USUAL_KINDS + [("slack", "backbone3"), ("friction", "lost motion"), ("toe", "slack"),
                                 "sharp friction", "tracker drift"]
#: The fifty-third fresh held-out batch (issue 19, drawn a session after bench-heldout52, the diagnosis unchanged since):
#: record shapes drawn per file as bench-shapes' (the three tubes, 25-200 Hz), a toe beside a relaxing backbone, lost
#: motion beside slack, a creeping tendon beside a guide's friction: pairs no batch above drew.
HELDOUT53_KINDS = USUAL_KINDS + [("toe", "backbone"), ("lost motion", "slack"), ("creep", "friction"),
                                 "sharp friction", "tracker drift"]
#: The fifty-fourth fresh held-out batch (issue 19, drawn a session after bench-heldout53, the diagnosis unchanged
#: since but for a refusal of fewer than ten rows): record shapes drawn per file as bench-shapes', a three-arm backbone
#: beside a guide's friction, a toe beside a sharp guide, a lag beside a sharp guide.
HELDOUT54_KINDS = USUAL_KINDS + [("backbone3", "friction"), ("toe", "sharp friction"), ("lag", "sharp friction"),
                                 "sharp friction", "tracker drift"]
#: The fifty-fifth fresh held-out batch (issue 19, drawn once a chain explaining 98 % of the misfit within 3x the floor
#: was recommended as partial, bench-heldout54 looked at): record shapes drawn per file, a three-arm backbone beside
#: lost motion, creep beside a sharp guide, slack beside a relaxing backbone.
HELDOUT55_KINDS = USUAL_KINDS + [("backbone3", "lost motion"), ("creep", "sharp friction"), ("slack", "backbone"),
                                 "sharp friction", "tracker drift"]
#: The fifty-sixth fresh held-out batch (issue 19, drawn a session after bench-heldout55, the diagnosis unchanged since):
#: record shapes drawn per file, lost motion beside a creeping tendon, a toe beside a three-arm backbone, a drifting
#: load-cell zero beside a guide's friction: pairs no batch above drew.
HELDOUT56_KINDS = USUAL_KINDS + [("lost motion", "creep"), ("toe", "backbone3"), ("zero drift", "friction"),
                                 "sharp friction", "tracker drift"]
#: The fifty-seventh fresh held-out batch (issue 19, drawn after the session's exact speed changes, the diagnosis's
#: results unchanged since bench-heldout56): record shapes drawn per file, a drifting load-cell zero beside a toe, a
#: relaxing backbone beside a sharp guide, a creeping tendon beside slack.
HELDOUT57_KINDS = USUAL_KINDS + [("zero drift", "toe"), ("backbone", "sharp friction"), ("creep", "slack"),
                                 "sharp friction", "tracker drift"]
#: Batches whose files draw their own record shapes (``draw_batch(shapes=True)``).
SHAPED = {"bench-shapes", "bench-heldout52", "bench-heldout53", "bench-heldout54", "bench-heldout55",
           "bench-heldout56", "bench-heldout57"}
BATCHES = {"bench": (20261124, TUNE_KINDS), "bench-sharp": (20281128, SHARP_KINDS),
           "bench-heldout": (20261207, HELDOUT_KINDS),
           "bench-heldout2": (20261224, HELDOUT2_KINDS), "bench-heldout3": (20261225, HELDOUT3_KINDS),
           # drawn once each sample diagnosed alone was settled (bench-heldout3 had been looked at): the third
           # batch's composition, a seed not used before; run once
           "bench-heldout4": (20261226, HELDOUT3_KINDS),
           # drawn once each sample diagnosed alone was restricted to samples each explained alone (a test of
           # an effect the library lacks caught the looser rule): the same composition, a seed not used before
           "bench-heldout5": (20261227, HELDOUT3_KINDS),
           # drawn once capstan, the guide's law at rest and the lag regression's friction terms were settled
           # (the tuned batch and the earlier held-out batches had been looked at): a seed not used before, with
           # guide friction beside a toe in one file; run once
           "bench-heldout6": (20261228, HELDOUT6_KINDS),
           # drawn once relaxation (the joint's backbone) and the baseline's stand-ins were settled (every batch
           # above had been looked at): a seed not used before, with a backbone beside a toe; run once
           "bench-heldout7": (20261229, HELDOUT7_KINDS),
           # drawn once the hardstop's plateau check and the retry of an empty round were settled (every batch
           # above had been looked at): a seed not used before, with two new pairs; run once
           "bench-heldout8": (20261230, HELDOUT8_KINDS),
           # drawn once carriage_hold (lost motion in the drive) was settled (every batch above had been looked
           # at): a seed not used before, with lost motion beside a toe and beside a creeping tendon; run once
           "bench-heldout9": (20261231, HELDOUT9_KINDS), "bench-heldout10": (20270115, HELDOUT10_KINDS),
           # drawn once the changes of the session after bench-heldout10 were settled (every batch above looked at)
           "bench-heldout11": (20270203, HELDOUT11_KINDS),
           # drawn once the changes of the session after bench-heldout11 were settled (every batch above looked at)
           "bench-heldout12": (20270311, HELDOUT12_KINDS),
           # drawn once the changes of the session after bench-heldout12 were settled (every batch above looked at)
           "bench-heldout13": (20270412, HELDOUT13_KINDS),
           # drawn once the changes of the session after bench-heldout13 were settled (every batch above looked at)
           "bench-heldout14": (20270520, HELDOUT14_KINDS),
           # drawn once bursts, a frozen tracker and correlated noise were settled (every batch above looked at),
           # each tracker's artefacts drawn too (ROUGH); run once
           "bench-heldout15": (20270621, HELDOUT15_KINDS),
           # drawn once the credit of a baseline's stand-in was settled (every batch above looked at), each
           # tracker's artefacts drawn too (ROUGH); run once
           "bench-heldout16": (20270722, HELDOUT16_KINDS),
           # drawn once the instruments' checks of the session after bench-heldout16 were settled (every batch above
           # looked at), with the instruments of rougher_instruments (ROUGHER); run once
           "bench-heldout17": (20270823, HELDOUT17_KINDS),
           # drawn once the overlapping bursts of the session after bench-heldout17 were settled (every batch above
           # looked at), with the instruments of rougher_instruments (ROUGHER); run once
           "bench-heldout18": (20270924, HELDOUT18_KINDS),
           # drawn once the jumps' pairing within the noise was settled (every batch above looked at), ROUGHER; run once
           "bench-heldout19": (20271026, HELDOUT19_KINDS),
           # drawn once the speed across rows set aside and the hold of what the rows do not resolve were settled
           # (every batch above looked at), ROUGHER; run once
           "bench-heldout20": (20271127, HELDOUT20_KINDS),
           # drawn once an unresolved parameter was measured against what its effect does (every batch above looked
           # at), ROUGHER; run once
           "bench-heldout21": (20271228, HELDOUT21_KINDS),
           # drawn once a burst with a dropout in it, an infinite standard error and a law at its sharp limit were
           # settled (every batch above looked at), ROUGHER; run once
           "bench-heldout22": (20280126, HELDOUT22_KINDS),
           # drawn once the carriage that settles and the drop kept to the resting effects' checks were settled
           # (every batch above looked at), ROUGHER, SETTLED; run once
           "bench-heldout23": (20280227, HELDOUT23_KINDS),
           # drawn once the union of the samples' chains held a copy the rows barely depend on (every batch above
           # looked at), ROUGHER, SETTLED; run once
           "bench-heldout24": (20280328, HELDOUT24_KINDS),
           "bench-heldout25": (20280521, HELDOUT25_KINDS),
           # drawn once the rows the load cell reads ahead of (or behind) the stroke, the lag regression's same angles
           # and the guide's sharp limit were settled (every batch above looked at, bench-sharp tuned on); run once
           "bench-heldout26": (20280622, HELDOUT26_KINDS),
           # drawn once those were settled (every batch above looked at, bench-heldout26 traced); run once
           "bench-heldout27": (20281129, HELDOUT27_KINDS),
           # drawn once the lag per sample was settled (bench-heldout27 traced); run once
           "bench-heldout28": (20281201, HELDOUT28_KINDS),
           # drawn once the model's test of the samples' own lags was settled (bench-heldout28 traced); run once
           "bench-heldout29": (20281202, HELDOUT29_KINDS),
           # drawn once the floor's spacing per sample was settled (bench-heldout29 rerun); run once
           "bench-heldout30": (20281203, HELDOUT30_KINDS),
           # drawn once the floor read further apart by a better model was settled (bench-heldout27, 29, 30 rerun);
           # run once
           "bench-heldout31": (20281204, HELDOUT31_KINDS),
           # drawn once a swap's replacement in the place of what it replaces was settled (bench-heldout27 .. 31
           # rerun); run once
           "bench-heldout32": (20281205, HELDOUT32_KINDS),
           # drawn once the union's copy held at its off value was settled (bench-heldout32 traced); run once
           "bench-heldout33": (20281206, HELDOUT33_KINDS),
           # drawn once the gain on the log scale and the lag tested in another sample were settled (bench-heldout32 and
           # 33 traced); run once
           "bench-heldout34": (20281207, HELDOUT34_KINDS),
           # drawn once an effect refused in some samples only was fitted in the others (bench-heldout24's lost motion
           # beside a backbone traced; the lost-motion and backbone files of bench-heldout20 .. 34 rerun); run once
           "bench-heldout35": (20281208, HELDOUT35_KINDS),
           # drawn once a tracker's fixed value beside a long burst was left out of its reading and what is left was
           # read against the model's bend angle (bench-heldout35's tracker drift traced; the tracker-drift files of
           # bench-heldout11 .. 35 rerun); run once
           "bench-heldout36": (20281209, HELDOUT36_KINDS),
           # drawn once a release the stroke had not logged under a cell at its limit was set aside, with a burst over
           # the guide's switch (bench-heldout36's sharp guide traced; the instruments' check of bench-sharp and
           # bench-heldout17 .. 36 compared); run once
           "bench-heldout37": (20281210, HELDOUT37_KINDS),
           # drawn once the diagnosis's speed steps were settled (the same answers, bit for bit, on bench-heldout33 and
           # 34: the sample-wise union's orders sharing their steps, toe_shape's compiled rows, this process working
           # beside one forked worker); run once
           "bench-heldout38": (20281211, HELDOUT38_KINDS),
           # drawn once the measurement files' checks were settled (the search as for bench-heldout38: a measure of the
           # settled method on pairs not drawn before); run once
           "bench-heldout39": (20281212, HELDOUT39_KINDS),
           # drawn once a lag under a load cell at its limit was read against the stroke (bench-heldout39 looked at);
           # run once
           "bench-heldout40": (20281213, HELDOUT40_KINDS),
           # drawn once a cell not zeroed was re-zeroed where the rests say so (bench-heldout40 looked at); run once
           "bench-heldout41": (20281214, HELDOUT41_KINDS),
           # drawn once the cell's zero was read whole where the joint at rest is nearly straight; run once
           "bench-heldout42": (20281215, HELDOUT42_KINDS),
           # drawn once the lag scan's normal equations were settled (bench-heldout40 .. 42 looked at); run once
           "bench-heldout43": (20281216, HELDOUT43_KINDS),
           # drawn once the cell's reading before the first pull was settled (bench-heldout43 looked at); run once
           "bench-heldout44": (20281217, HELDOUT44_KINDS),
           # drawn once the limit's rows were left out of the force's noise scale (bench-heldout44 looked at); run once
           "bench-heldout45": (20281218, HELDOUT45_KINDS),
           # drawn to measure the final method of the session after bench-heldout45 (every batch above looked at);
           # run once
           "bench-heldout46": (20281219, HELDOUT46_KINDS),
           # drawn once the session's changes after bench-heldout46 were settled (bench-heldout44 and 46 looked at);
           # run once
           "bench-heldout47": (20281220, HELDOUT47_KINDS),
           # drawn to measure the method settled after bench-heldout47 (every batch above looked at); run once
           "bench-heldout48": (20281221, HELDOUT48_KINDS),
           # drawn once a small drift alike at rest and under load was named (every batch above looked at); run once
           "bench-heldout49": (20281222, HELDOUT49_KINDS),
           # drawn once the drive's history ran through the rows set aside for the angle alone (every batch above
           # looked at); run once
           "bench-heldout50": (20281223, HELDOUT50_KINDS),
           # drawn to measure the method settled after bench-heldout50 (every batch above looked at); run once
           "bench-heldout51": (20281224, HELDOUT51_KINDS),
           # drawn once bench-heldout51 had run, with record shapes the batches above lack (SHAPED); run once
           "bench-shapes": (20281225, SHAPES_KINDS),
           # drawn once the method was settled after bench-heldout51 and bench-shapes (both looked at); run once
           "bench-heldout52": (20281226, HELDOUT52_KINDS),
           # drawn a session after bench-heldout52 (looked at), the diagnosis unchanged since; run once
           "bench-heldout53": (20281227, HELDOUT53_KINDS),
           # drawn a session after bench-heldout53 (looked at), the diagnosis unchanged since; run once
           "bench-heldout54": (20281228, HELDOUT54_KINDS),
           # drawn once the partial label's second tier was settled (bench-heldout54 looked at); run once
           "bench-heldout55": (20281229, HELDOUT55_KINDS),
           # drawn a session later, the diagnosis unchanged since bench-heldout55; run once
           "bench-heldout56": (20281230, HELDOUT56_KINDS),
           # drawn after the session's exact speed changes (results unchanged since bench-heldout56); run once
           "bench-heldout57": (20281231, HELDOUT57_KINDS)}
#: Batches whose carriages settle (:func:`settle_drives`); those before keep the law they were drawn with, where a
#: carriage pulled off its rail's hold lands on the nut's flank in one step.
SETTLED = {"bench-heldout23", "bench-heldout24", "bench-heldout25", "bench-heldout26", "bench-heldout27",
           "bench-heldout28", "bench-heldout29", "bench-heldout30", "bench-heldout31", "bench-heldout32",
           "bench-heldout33", "bench-heldout34", "bench-heldout35", "bench-heldout36", "bench-heldout37",
           "bench-heldout38", "bench-heldout39", "bench-heldout40", "bench-heldout41", "bench-heldout42",
           "bench-heldout43", "bench-heldout44", "bench-heldout45", "bench-sharp", "bench-heldout46",
           "bench-heldout47", "bench-heldout48", "bench-heldout49", "bench-heldout50",
           "bench-heldout51", "bench-shapes",
           "bench-heldout52", "bench-heldout53", "bench-heldout54", "bench-heldout55",
           "bench-heldout56", "bench-heldout57"}
#: Batches whose trackers' artefacts are drawn too (:func:`rough_instruments`): dropouts written as values, bursts,
#: filtered noise.
ROUGH = {"bench-heldout15", "bench-heldout16"}
#: Batches with those, interference lasting seconds and load cells that reach their range
#: (:func:`rougher_instruments`).
ROUGHER = {"bench-sharp", "bench-heldout17", "bench-heldout18", "bench-heldout19", "bench-heldout20",
           "bench-heldout21", "bench-heldout22", "bench-heldout23", "bench-heldout24", "bench-heldout25",
           "bench-heldout26", "bench-heldout27", "bench-heldout28", "bench-heldout29", "bench-heldout30",
           "bench-heldout31", "bench-heldout32", "bench-heldout33", "bench-heldout34", "bench-heldout35",
           "bench-heldout36", "bench-heldout37", "bench-heldout38", "bench-heldout39", "bench-heldout40",
           "bench-heldout41", "bench-heldout42", "bench-heldout43", "bench-heldout44", "bench-heldout45",
           "bench-heldout46", "bench-heldout47", "bench-heldout48", "bench-heldout49", "bench-heldout50",
           "bench-heldout51", "bench-shapes",
           "bench-heldout52", "bench-heldout53", "bench-heldout54", "bench-heldout55",
           "bench-heldout56", "bench-heldout57"}
#: Batches whose load cells may not be zeroed before the test (:func:`untared`).
UNTARED = {"bench-heldout41", "bench-heldout42", "bench-heldout43", "bench-heldout44", "bench-heldout45",
           "bench-heldout46", "bench-heldout47", "bench-heldout48", "bench-heldout49", "bench-heldout50",
           "bench-heldout51", "bench-shapes",
           "bench-heldout52", "bench-heldout53", "bench-heldout54", "bench-heldout55",
           "bench-heldout56", "bench-heldout57"}


def _lag_found(lag_ms: float, se_ms: float, applied_ms: float, true_ms: float, row_ms: float) -> bool:
    """A lag found (within 3 standard errors or 20 %) and corrected by whole rows (within one row of the estimate);
    where there is none, none corrected."""
    if true_ms <= 0.0:
        return applied_ms == 0.0
    return (applied_ms > 0 and abs(lag_ms - true_ms) <= max(3.0 * se_ms, 0.2 * true_ms)
            and abs(applied_ms - lag_ms) <= row_ms + 1e-6)


def lag_right(lag, true_ms: list, row_ms: float) -> bool:
    """The instruments' lag against the samples' true lags: each sample's own where they were read per sample, else
    the one lag against their common lag (wrong where the samples' trackers lag differently)."""
    if lag.per_sample:
        return all(_lag_found(ms, se, applied, true, row_ms)
                   for (_, ms, se, _, applied), true in zip(lag.per_sample, true_ms))
    return len(set(true_ms)) == 1 and _lag_found(lag.lag_ms, lag.se_ms, lag.applied_ms, true_ms[0], row_ms)


def run_file(spec, workdir: Path, verbose: bool = True) -> dict:
    """Simulate, write, read back, check the instruments and diagnose one file; a dict of the figures."""
    name, tube, rate, benches, kinds, seed = spec[:6]
    pattern = load_pattern(ROOT / "patterns" / f"{tube}.yaml")
    rec = simulate_bench(pattern, benches, protocol_of(spec), Clock(rate_hz=rate), seed=seed)
    path = workdir / f"bench_{seed}.csv"
    path.write_text(format_csv(rec.data))
    t0 = time.perf_counter()
    meas = read_measurements(path)
    ins = check_instruments(meas.data, dropped=meas.summary(), n_dropped=meas.missing_lines.size)
    model = model_for_pattern(pattern)
    ins = confirm_lag(ins, model, pattern_values(pattern))   # as camtube model diagnose does
    t1 = time.perf_counter()
    d = diagnose(model, ins.data, ["E_t"], pattern_values(pattern))
    t2 = time.perf_counter()
    rec_list = list(d.recommended)
    final = d.final.rmse_deg
    floor_true = rec.floor_deg
    lag_true = benches[0].tracker.lag_ms
    right = set()
    for k in kinds:
        right |= FAMILIES[k][0]
    first = rec_list[0] if rec_list else "-"
    if kinds[0] == "lag":
        # an instrument property: found (within 3 standard errors or 20 %) and corrected (by whole rows: within one
        # row of the estimate), never offered as a joint effect; the secondary mechanisms may still be explained,
        # to the floor. (Until bench-heldout25 the whole rows applied were compared with the truth within 3 standard
        # errors: a lag of 27 ms read 27.3 +- 0.8 and applied as one row of 20 ms at 50 Hz counted wrong)
        # (a file whose second sample has no lag, "lag / creep": each sample's own, none corrected where none is)
        lag_ok = lag_right(ins.lag, [b.tracker.lag_ms for b in benches], 1e3 / rate)
        ok = lag_ok and (not rec_list or final <= 1.15 * floor_true)
    elif kinds[0] == "zero drift" and ins.rezeroed:
        # an instrument property read at the rests and corrected (as a lag is); what the bench's other mechanisms
        # leave is explained to the floor (its own mild creep among them: once the drift is gone, a creep that
        # shows is the tendon's, as in a lag file)
        ok = not rec_list or final <= 1.15 * floor_true
    elif not right:
        ok = not rec_list
    else:
        ok = bool(rec_list) and rec_list[0] in right and final <= 1.15 * floor_true
        if kinds[0] != kinds[1]:
            ok = bool(rec_list) and set(rec_list) >= {next(iter(FAMILIES[k][0] & set(rec_list)), None) or "?" for k in kinds}
    floor_ok = abs(d.noise_floor_deg / floor_true - 1.0) <= 0.2
    from camtube.model.unexplained import report as unexplained_report

    u = unexplained_report.of_diagnosis(d)
    if kinds == ("control", "control"):
        # the paper's physics: nothing recommended and nothing unexplained (until this session a control was scored on
        # the first alone; bench-heldout44's control had 1.26x the floor "unexplained", an overlapping burst kept)
        ok = ok and u is None
    left = (u.get("follows") or ["-"])[0] if u else "-"
    want = FAMILIES[kinds[0]][1]
    tied = list(u.get("tied") or []) if u else []
    if want is not None and not (kinds[0] == "zero drift" and ins.rezeroed):
        # the library lacks it: nothing of a wrong family, and what is left follows `want` (first, or tied with the
        # first: the report names both, "these data cannot tell them apart")
        ok = ok and (left == want or want in tied)
    out = dict(name=name, tube=tube, rate=rate, rows=len(rec.data), first=first, recommended=rec_list,
               partial=list(d.partial), explanation=d.explanation, base=d.waterfall[0].rmse_deg, final=final, floor_est=d.noise_floor_deg,
               floor_true=floor_true, floor_ok=floor_ok, left=left, lag_true=lag_true, lag_est=ins.lag.lag_ms,
               lag_se=ins.lag.se_ms, lag_applied=ins.lag.applied_ms, n_aside=ins.n_aside,
               n_dropped=meas.missing_lines.size, spikes_true=len(rec.spike_rows), ok=ok,
               s_instruments=t1 - t0, s_diagnose=t2 - t1)
    if verbose:
        print(f"{name:18s} {tube} {rate:4.0f} Hz {len(rec.data):6d} rows | first {first:11s} rec {','.join(rec_list) or '-':24s}"
              f" {d.explanation or '-':8s} partial {','.join(d.partial) or '-':18s} RMSE {out['base']:.3f} -> {final:.3f} deg ({final / floor_true:.2f} x true floor; partial chain "
              f"{(d.partial_steps[-1].rmse_deg / floor_true) if d.partial else float('nan'):.2f} x) | floor est "
              f"{d.noise_floor_deg:.3f} true {floor_true:.3f} ({'ok' if floor_ok else 'OFF'}) | lag {lag_true:.0f} -> "
              f"{ins.lag.lag_ms:.1f}+-{ins.lag.se_ms:.1f} ms (applied {ins.lag.applied_ms:.1f})"
              + "".join(f" {smp} {ms:.1f}+-{se:.1f} (applied {a:.1f}; true {b.tracker.lag_ms:.0f})"
                        for (smp, ms, se, _, a), b in zip(ins.lag.per_sample, benches))
              + f" | left follows {left}"
              f"{' (or ' + ', '.join(tied) + ')' if tied else ''} | aside {ins.n_aside} "
              f"(spikes {len(rec.spike_rows)}), dropped {meas.missing_lines.size}"
              f"{' | rezeroed ' + ','.join(s for s, z in ins.zeros.items() if z.applied) if ins.rezeroed else ''}"
              f" | {'RIGHT' if ok else 'wrong'} | "
              f"{t1 - t0:.1f}+{t2 - t1:.1f} s", flush=True)
    return out


def settle_drives(specs: list) -> list:
    """``specs`` with every sample's carriage settling (:attr:`Drive.settle`): pulled off its rail's hold, it
    slides only until the tension is back at the friction, rather than landing on the nut's flank."""
    return [(name, tube, rate, tuple(replace(b, drive=replace(b.drive, settle=True)) for b in benches), kinds, seed,
             *rest) for name, tube, rate, benches, kinds, seed, *rest in specs]


def batch_specs(name: str, settled: bool = False) -> list:
    """The files of batch ``name`` (:func:`draw_batch`; the batches of :data:`ROUGH` with their trackers' artefacts;
    those of :data:`SETTLED`, or all with ``settled``, with their carriages settling, :func:`settle_drives`)."""
    seed, kinds = BATCHES[name]
    specs = draw_batch(seed, kinds, rough=name in ROUGH, rougher=name in ROUGHER, untared_cells=name in UNTARED,
                       shapes=name in SHAPED)
    return settle_drives(specs) if settled or name in SETTLED else specs


def run_batch(name: str, settled: bool = False, only: str = "") -> list:
    specs = [s for s in batch_specs(name, settled) if only in s[0]]
    with tempfile.TemporaryDirectory() as tmp:
        res = [run_file(s, Path(tmp)) for s in specs]
    n_ok = sum(r["ok"] for r in res)
    n_floor = sum(r["floor_ok"] for r in res)
    per_60k = [(r["s_instruments"] + r["s_diagnose"]) * 60_000 / r["rows"] for r in res]
    label = name + (" (carriages settling)" if settled and name not in SETTLED else "") + (f" ({only!r} only)" if only else "")
    print(f"{label}: {n_ok} of {len(res)} right; noise floor within 20 % of the true one in {n_floor} of {len(res)}; "
          f"seconds per 60,000-row file: median {np.median(per_60k):.1f}, max {max(per_60k):.1f}")
    return res


def write_file(batch: str, kind: str, path: str) -> None:
    """Write the file of ``kind`` of ``batch`` as CSV, as a lab would have it: its name in the batch's table (the
    first file of that name) or its 0-based index (a batch with two files of one name)."""
    import sys

    if batch not in BATCHES:
        print(f"bench_real.py --write: no batch {batch!r}; fix: one of {', '.join(BATCHES)}", file=sys.stderr)
        sys.exit(2)
    specs = batch_specs(batch)
    spec = next((s for s in specs if s[0] == kind), None)
    if spec is None and kind.isdigit() and int(kind) < len(specs):
        spec = specs[int(kind)]
    if spec is None:
        print(f"bench_real.py --write: {batch} has no file {kind!r}; fix: give a name or an index: "
              + ", ".join(f"{i} {s[0]!r}" for i, s in enumerate(specs)), file=sys.stderr)
        sys.exit(2)
    name, tube, rate, benches, _, sim_seed = spec[:6]
    pattern = load_pattern(ROOT / "patterns" / f"{tube}.yaml")
    rec = simulate_bench(pattern, benches, protocol_of(spec), Clock(rate_hz=rate), seed=sim_seed)
    Path(path).write_text(format_csv(rec.data))
    print(f"wrote {path}: {name}, {tube}, {rate:g} Hz, {len(rec.data)} rows; true floor {rec.floor_deg:.3f} deg, "
          f"spikes {len(rec.spike_rows)}, missing angles {len(rec.dropout_rows)}")


if __name__ == "__main__":
    import sys

    args = sys.argv[1:]
    if args[:1] in (["-h"], ["--help"]):
        print(__doc__ + "\nUsage: python scripts/bench_real.py [--settled] [--only NAME] [BATCH ...] | --write BATCH KIND|INDEX OUT.csv\n"
              "--settled: every carriage settles (Drive.settle); --only: the files whose name holds NAME\nBatches: "
              + ", ".join(BATCHES))
    elif args[:1] == ["--write"]:  # --write BATCH KIND OUT.csv
        if len(args) != 4:
            print("usage: python scripts/bench_real.py --write BATCH KIND OUT.csv", file=sys.stderr)
            sys.exit(2)
        write_file(*args[1:4])
    else:
        settled = "--settled" in args
        only = ""
        if "--only" in args:
            k = args.index("--only")
            if k + 1 >= len(args):
                print("bench_real.py --only: give part of a file's name, e.g. --only 'lost motion'", file=sys.stderr)
                sys.exit(2)
            only = args[k + 1]
            del args[k:k + 2]
        args = [a for a in args if a != "--settled"]
        unknown = [b for b in args if b not in BATCHES]
        if unknown:
            print(f"unknown batch {unknown[0]!r}; fix: give one of {', '.join(BATCHES)}", file=sys.stderr)
            sys.exit(2)
        for b in args or ["bench"]:
            run_batch(b, settled, only)
