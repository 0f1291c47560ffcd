#!/usr/bin/env python3
"""Independent time-stepped simulator of a tendon-driven notched polyimide joint bench.

Written (issue 19, session of 2026-12-07) by a helper who had the issue's text and the source paper only and did not
read camtube's code: its forms (an exponential toe, a backlash whose carriage stays at the far flank, a Kelvin creep, a
standard-linear-solid backbone) are not the effect library's, nor those of ``camtube.model.sim.bench``. Keep it so:
do not tune it to the diagnosis. ``scripts/indep_bench/run.py`` draws its batches, diagnoses them and scores them.

Components (each its own function / state):
  motor + lead screw (commanded stroke profile) -> [optional lost motion: play operator, rail holds carriage]
  -> carriage -> load cell (noise, optional slow zero drift) -> [optional guide: capstan friction]
  -> tendon (optional slack deadband, toe region, Kelvin creep) -> joint backbone (bending stiffness,
  optional standard-linear-solid relaxation + permanent set) -> EM tracker (noise, spikes, dropouts,
  optional lag, optional slow zero drift).
Equilibrium each step: carriage_pos - slack = arm*theta + e_tendon(F_seg) + creep, F_joint = M(theta)/arm.
"""
import json, math, sys
import numpy as np

PRESETS = {  # r_o, r_i, s, stroke max
    'tube1': (0.75, 0.45, 2.83, 2.0),
    'tube2': (0.85, 0.55, 3.20, 2.5),
    'tube3': (1.25, 0.75, 4.71, 5.0),
}
R_T, L0, N_NOTCH, H_NOTCH = 0.04, 70.0, 10, 0.5


def geometry(tube):
    ro, ri, s, smax = PRESETS[tube]
    phi = (2 * math.pi * ro - s) / ro
    ybar = 4 * math.sin(phi / 2) * (ro**3 - ri**3) / (3 * phi * (ro**2 - ri**2))
    arm = ybar + ri - R_T
    # second moment of the annular sector (remaining backbone) about its own centroidal axis
    Ic = (ro**4 - ri**4) / 4 * (phi / 2 + math.sin(phi) / 2)
    A = phi / 2 * (ro**2 - ri**2)
    I = Ic - A * ybar**2
    return dict(phi=phi, ybar=ybar, arm=arm, I=I, smax=smax)


def smooth_ramp(u):
    u = np.clip(u, 0, 1)
    return 0.5 - 0.5 * np.cos(np.pi * u)


def slow_curve(rng, t, amp, T):
    """smooth random slow drift, zero at t=0, rms-ish amplitude amp, time scale T"""
    n = 4
    y = np.zeros_like(t)
    for k in range(1, n + 1):
        y += rng.normal() / k * np.sin(2 * np.pi * k * t / (T * 4) + rng.uniform(0, 2 * np.pi))
    y -= y[0]
    y *= amp / max(np.std(y), 1e-9)
    return y


def simulate_sample(rng, tube, rate, ncyc, rows_target, p, name):
    g = geometry(tube)
    arm = g['arm']
    smax = g['smax'] * p.get('stroke_frac', 1.0)
    E_b = p['E_b']  # backbone modulus N/mm^2
    K = E_b * g['I'] / (N_NOTCH * H_NOTCH)  # N mm / rad (10 flexures in series)
    c_el = L0 / (p['E_t'] * math.pi * R_T**2)  # mm/N
    dt = 1.0 / rate
    # protocol: total time per cycle from rows target
    Tc = rows_target / ncyc * dt
    fr = rng.uniform(0.28, 0.34); fd = rng.uniform(0.1, 0.15)
    Tr, Td = fr * Tc, fd * Tc
    Trest = Tc - 2 * Tr - Td
    Td1 = Td * p.get('first_dwell_factor', 3.0)
    # build cycle table
    starts = []; t0 = 0.0
    for c in range(ncyc):
        dd = Td1 if c == 0 else Td
        starts.append((t0, dd)); t0 += 2 * Tr + dd + Trest
    Ttot = t0
    nrows = int(Ttot / dt)
    jit = p.get('jitter_frac', 0.05)
    t = np.arange(nrows) * dt + rng.normal(0, jit * dt, nrows)
    t[0] = max(t[0], 0.0)
    t = np.maximum.accumulate(t + 1e-9)
    cyc = np.zeros(nrows, int); xm = np.zeros(nrows)
    for c, (ts, dd) in enumerate(starts):
        te = ts + 2 * Tr + dd + Trest
        m = (t >= ts) & (t < te)
        cyc[m] = c + 1
        u = t[m] - ts
        x = np.where(u < Tr, smooth_ramp(u / Tr),
             np.where(u < Tr + dd, 1.0, np.where(u < 2 * Tr + dd, 1 - smooth_ramp((u - Tr - dd) / Tr), 0.0)))
        xm[m] = smax * x
    cyc[cyc == 0] = ncyc
    # --- drive: lost motion (play operator; rail friction holds the carriage) ---
    b = p.get('backlash_mm', 0.0)
    xc = np.empty(nrows)
    pos = 0.0
    for k in range(nrows):
        if b > 0:
            if xm[k] > pos: pos = xm[k]
            elif xm[k] < pos - b: pos = xm[k] + b
        else:
            pos = xm[k]
        xc[k] = pos
    # --- tendon / joint time stepping ---
    slack = p.get('slack_mm', 0.0)
    toe_d, toe_F = p.get('toe_mm', 0.0), p.get('toe_F', 0.5)
    cr_a, cr_tau = p.get('creep_mm_per_N', 0.0), p.get('creep_tau', 60.0)
    K1, rtau = p.get('relax_frac', 0.0) * K, p.get('relax_tau', 10.0)
    set_rate = p.get('set_rate', 0.0)  # 1/s rate at which the set follows the bend (tiny)
    mub = p.get('capstan_mub', 0.0)
    q = 0.0; thp = 0.0; ecr = 0.0; dirst = 1.0
    th = np.zeros(nrows); Fj = np.zeros(nrows); Fc = np.zeros(nrows)
    prev = 0.0
    for k in range(nrows):
        h = t[k] - t[k - 1] if k else dt
        v = xc[k] - prev; prev = xc[k]
        if abs(v) > 1e-7: dirst = math.copysign(1.0, v)
        cap = math.exp(mub * dirst)  # F_cell = cap * F_joint
        s_eff = xc[k] - slack - ecr
        # moment M(theta) = K (th - thp) + K1 (th - q); F_joint = M/arm
        Kt = K + K1
        th_free = (K * thp + K1 * q) / Kt
        def gfun(thv):
            F = max(Kt * thv - K * thp - K1 * q, 0.0) / arm
            Fs = F * (1 + cap) / 2  # mean tension along the tendon (guide mid-way)
            e = c_el * Fs + toe_d * (1 - math.exp(-Fs / toe_F))
            return arm * thv + e - s_eff, F
        if arm * th_free >= s_eff:
            thv, F = th_free, 0.0
        else:
            lo, hi = th_free, th_free + (s_eff - arm * th_free) / arm
            for _ in range(50):
                mid = 0.5 * (lo + hi)
                if gfun(mid)[0] > 0: hi = mid
                else: lo = mid
            thv = 0.5 * (lo + hi); F = gfun(thv)[1]
        th[k] = thv; Fj[k] = F; Fc[k] = F * cap
        # state updates (explicit, h << taus)
        if K1 > 0: q += (thv - q) * min(h / rtau, 1.0)
        if set_rate > 0: thp += set_rate * (thv - thp) * h
        if cr_a > 0: ecr += (cr_a * F * (1 + cap) / 2 - ecr) * min(h / cr_tau, 1.0)
    # --- instruments ---
    stroke_rep = np.round(xm / 1e-4) * 1e-4
    fz = slow_curve(rng, t, p['fz_drift_N'], Ttot) if p.get('fz_drift_N', 0) > 0 else 0.0
    F_meas = Fc + rng.normal(0, p['F_noise'], nrows) + fz
    ang_true = np.degrees(th)
    lag = p.get('lag_ms', 0.0) / 1000.0
    ang_seen = np.interp(t - lag, t, ang_true) if lag > 0 else ang_true.copy()
    az = slow_curve(rng, t, p['az_drift_deg'], Ttot) if p.get('az_drift_deg', 0) > 0 else 0.0
    noise = rng.normal(0, p['ang_noise'], nrows)
    spikes = np.zeros(nrows)
    nsp = rng.integers(4, 10)
    idx = rng.choice(nrows, nsp, replace=False)
    for i in idx:
        L = rng.integers(1, 4)
        spikes[i:i + L] = rng.choice([-1, 1]) * rng.uniform(3, 10)
    ang_meas = ang_seen + az + noise + spikes
    # dropouts
    drop = np.zeros(nrows, bool)
    for _ in range(rng.integers(3, 9)):
        i = rng.integers(0, nrows - 20); drop[i:i + rng.integers(2, 15)] = True
    art = noise + spikes
    # floor: angle noise+spikes, plus the force-noise propagated through the elongation term
    fprop = np.degrees(c_el * p['F_noise'] / arm)
    floor_all = float(np.sqrt(np.mean(art[~drop]**2) + fprop**2))
    floor_nospk = float(np.sqrt(np.mean(noise[~drop]**2) + fprop**2))
    info = dict(sample=name, K_Nmm_per_rad=K, c_el_mm_per_N=c_el, arm_mm=arm, rows=nrows,
                F_max=float(Fc.max()), theta_max_deg=float(ang_true.max()),
                floor_with_spikes=floor_all, floor_no_spikes=floor_nospk, force_noise_prop_deg=fprop,
                n_spikes=int(nsp), n_dropped=int(drop.sum()))
    return dict(t=t, cyc=cyc, stroke=stroke_rep, F=F_meas, ang=ang_meas, drop=drop, info=info,
                art=art[~drop])


MECH = {  # dominant (strong) and weak parameter draws; tube stroke scale handled by smax factor
    'toe':        lambda r, s, w: {'toe_mm': (0.012 if w else 0.04) * s * r.uniform(0.8, 1.2), 'toe_F': r.uniform(0.3, 0.8)},
    'slack':      lambda r, s, w: {'slack_mm': (0.015 if w else 0.06) * s * r.uniform(0.8, 1.2)},
    'lost_motion':lambda r, s, w: {'backlash_mm': (0.015 if w else 0.05) * s * r.uniform(0.8, 1.2)},
    'creep':      lambda r, s, w: {'creep_mm_per_N': (0.006 if w else 0.03) * r.uniform(0.8, 1.2), 'creep_tau': r.uniform(30, 120)},
    'relaxation': lambda r, s, w: {'relax_frac': (0.12 if w else 0.45) * r.uniform(0.8, 1.2), 'relax_tau': r.uniform(4, 20),
                                   'set_rate': (0.0 if w else 1e-4 * r.uniform(0.5, 1.5))},
    'capstan':    lambda r, s, w: {'capstan_mub': (0.04 if w else 0.2) * r.uniform(0.8, 1.2)},
    'fz_drift':   lambda r, s, w: {'fz_drift_N': (0.01 if w else 0.05) * r.uniform(0.8, 1.2)},
    'lag':        lambda r, s, w: {'lag_ms': r.uniform(20, 80) if not w else r.uniform(10, 20)},
    'az_drift':   lambda r, s, w: {'az_drift_deg': (0.3 if w else 1.5) * r.uniform(0.8, 1.2)},
}


def make_file(out, tube, seed, dom, weak, rate=None, dom2=None, et_var=0.0):
    rng = np.random.default_rng(seed)
    rate = rate or float(rng.choice([25, 50, 100]))
    smax = PRESETS[tube][3]
    base = dict(E_b=rng.uniform(2500, 3000), E_t=28000 * rng.uniform(0.9, 1.1), ang_noise=rng.uniform(0.1, 0.3),
                F_noise=rng.uniform(0.002, 0.006), jitter_frac=0.05)
    mech = {}
    for m in ([dom] if dom else []):
        mech.setdefault('S1', {}).update(MECH[m](rng, smax, False))
    for m in weak:
        mech.setdefault('S1', {}).update(MECH[m](rng, smax, True))
    lines = []; truth = dict(tube=tube, seed=seed, rate=rate, dominant={'S1': dom, 'S2': dom2 or dom}, weak=weak,
                             samples={})
    for si, nm in enumerate(['S1', 'S2']):
        p = dict(base)
        p['E_b'] *= (1 + rng.uniform(-0.2, 0.2)) if si else 1
        p['E_t'] *= (1 + rng.uniform(-et_var, et_var)) if si else 1
        p['ang_noise'] *= (1 + rng.uniform(-0.15, 0.15)) if si else 1
        mp = {}
        if si == 0 or dom2 is None:
            for k, v in mech.get('S1', {}).items():
                mp[k] = v * ((1 + rng.uniform(-0.15, 0.15)) if si else 1)
        else:
            mp.update(MECH[dom2](rng, smax, False))
            for m in weak:
                mp.update(MECH[m](rng, smax, True))
        p.update(mp)
        r = simulate_sample(rng, tube, rate, 50, 30000, p, nm)
        truth['samples'][nm] = dict(params=p, **r['info'])
        r['nm'] = nm
        lines.append(r)
    allart = np.concatenate([r['art'] for r in lines])
    truth['true_angle_noise_std'] = float(np.sqrt(np.mean([truth['samples'][n]['params']['ang_noise']**2 for n in ('S1', 'S2')])))
    fp = np.mean([truth['samples'][n]['force_noise_prop_deg']**2 for n in ('S1', 'S2')])
    truth['floor_with_spikes'] = float(np.sqrt(np.mean(allart**2) + fp))
    truth['floor_no_spikes'] = float(np.sqrt(truth['true_angle_noise_std']**2 + fp))
    with open(out, 'w') as f:
        f.write('sample,cycle,time_s,stroke_mm,force_N,angle_deg\n')
        for r in lines:
            for k in range(len(r['t'])):
                a = '' if (r['drop'][k] and k % 2) else ('nan' if r['drop'][k] else f"{r['ang'][k]:.4f}")
                f.write(f"{r['nm']},{r['cyc'][k]},{r['t'][k]:.4f},{r['stroke'][k]:.4f},{r['F'][k]:.5f},{a}\n")
    json.dump(truth, open(out.replace('.csv', '.truth.json'), 'w'), indent=1)
    return truth


if __name__ == '__main__':
    spec = json.loads(sys.argv[1])
    tr = make_file(**spec)
    print(json.dumps({k: tr['samples'][k]['F_max'] for k in tr['samples']}),
          {k: round(tr['samples'][k]['theta_max_deg'], 1) for k in tr['samples']}, tr['floor_with_spikes'], tr['rate'])
