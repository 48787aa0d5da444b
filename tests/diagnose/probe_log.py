#!/usr/bin/python3
"""An outsider's dual-gyro log generator (docs/log-format.md), written apart from twin/ and from
tests/diagnose/independent_log.py: numpy only, its own rotations and flip schedule.

Sensors (--sensor): mpu6050 (0.005 deg/s/rtHz, 131 LSB/dps, +-250 dps), bmi088 (0.014 deg/s/rtHz,
16.384 LSB/dps at +-2000 dps, turn-on bias up to 1 deg/s), tactical (0.003 deg/s/rtHz, no
quantisation, 0.05 deg/s turn-on bias, 1 deg/h instability), or explicit --noise/--lsb/--fs.

  probe_log.py --out log.csv --sensor bmi088 --rate 1000 --duration 300 --period 20 \
      --hinge1 0,1,0 --hinge2 0,0,1 --motion turn --drop 0.02 --dup 3 --gap 100:5 --seed 1
"""
import argparse
import math

import numpy as np

D2R = math.pi / 180.0
EARTH_RATE_DPS = 7.292115e-5 / D2R
SENSORS = {  # noise density deg/s/rtHz, LSB per deg/s (0: none), full scale deg/s, bias sigma deg/s, rw deg/s/rts
    "mpu6050": (0.005, 65.5, 500.0, 3.0, 1e-4),
    "bmi088": (0.014, 16.384, 2000.0, 0.5, 2e-4),
    "tactical": (0.003, 0.0, 400.0, 0.05, 3e-6),
}


def rot(axis, ang_rad):
    """Rotation matrices about a unit axis, vectorised over angles (Rodrigues)."""
    a = np.asarray(axis, float)
    a = a / np.linalg.norm(a)
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    ang = np.atleast_1d(ang_rad)
    s, c = np.sin(ang)[:, None, None], np.cos(ang)[:, None, None]
    return np.eye(3)[None] + s * k[None] + (1 - c) * (k @ k)[None]


def mat_to_quat(R):
    """q (w,x,y,z) of rotation matrices (Shepperd: the largest of w, x, y, z first)."""
    tr = R[:, 0, 0] + R[:, 1, 1] + R[:, 2, 2]
    cand = np.stack([1 + tr, 1 + 2 * R[:, 0, 0] - tr, 1 + 2 * R[:, 1, 1] - tr, 1 + 2 * R[:, 2, 2] - tr], 1)
    k = np.argmax(cand, 1)
    q = np.empty((len(R), 4))
    for i in range(4):
        m = k == i
        Rm = R[m]
        s = np.sqrt(np.maximum(cand[m, i], 1e-300)) * 2  # 4 * component
        d = {0: Rm[:, 2, 1] - Rm[:, 1, 2], 1: Rm[:, 0, 2] - Rm[:, 2, 0], 2: Rm[:, 1, 0] - Rm[:, 0, 1]}
        o = {(0, 1): Rm[:, 0, 1] + Rm[:, 1, 0], (0, 2): Rm[:, 0, 2] + Rm[:, 2, 0], (1, 2): Rm[:, 1, 2] + Rm[:, 2, 1]}
        comp = np.zeros((m.sum(), 4))
        comp[:, i] = s / 4
        if i == 0:
            comp[:, 1], comp[:, 2], comp[:, 3] = d[0] / s, d[1] / s, d[2] / s
        else:
            comp[:, 0] = d[i - 1] / s
            for j in (1, 2, 3):
                if j != i:
                    comp[:, j] = o[tuple(sorted((i - 1, j - 1)))] / s
        q[m] = comp * np.where(comp[:, :1] < 0, -1, 1)
    return q

def flip_profile(t, starts, flip_s):
    """Progress 0..1 of each flip and its rate (1/s): raised cosine, counted over all flips."""
    n = np.searchsorted(starts, t, side="right")  # flips started by t
    done = np.maximum(n - 1, 0)
    last = np.where(n > 0, starts[np.maximum(n - 1, 0)], -1e9)
    u = np.clip((t - last) / flip_s, 0, 1)
    s = u - np.sin(2 * math.pi * u) / (2 * math.pi)
    ds = np.where((u > 0) & (u < 1), (1 - np.cos(2 * math.pi * u)) / flip_s, 0.0)
    return done, np.where(n > 0, s, 0.0), ds, n


def platform(t, starts, flip_s, amp_deg):
    """Angle (deg) and rate (deg/s) of a platform flipping +amp -> -amp -> +amp at starts."""
    if len(starts) == 0:
        return np.full_like(t, amp_deg), np.zeros_like(t)
    done, s, ds, n = flip_profile(t, starts, flip_s)
    side0 = np.where(done % 2 == 0, 1.0, -1.0)  # side before the current flip
    before = np.where(n > 0, side0, 1.0) * amp_deg
    ang = before - 2 * before * s
    rate = -2 * before * ds
    return ang, rate


def box_motion(t, kind, rng):
    """R_enu_from_body (n,3,3) and body rate relative to ENU in body axes (deg/s)."""
    n = len(t)
    if kind == "static":
        return np.repeat(np.eye(3)[None], n, 0), np.zeros((n, 3))
    if kind == "turn":  # yaw sinusoid + roll sinusoid
        f1, f2 = 0.05, 0.13
        psi = 70 * D2R * np.sin(2 * math.pi * f1 * t)
        dpsi = 70 * 2 * math.pi * f1 * np.cos(2 * math.pi * f1 * t)
        phi = 20 * D2R * np.sin(2 * math.pi * f2 * t)
        dphi = 20 * 2 * math.pi * f2 * np.cos(2 * math.pi * f2 * t)
        Rz, Rx = rot([0, 0, 1], psi), rot([1, 0, 0], phi)
        R = Rz @ Rx
        w = np.einsum("nji,j->ni", Rx, np.array([0, 0, 1.0])) * dpsi[:, None]
        w[:, 0] += dphi
        return R, w
    if kind == "fast":  # a spin about body z reaching 600 deg/s (saturates a +-250 dps gyro)
        rate = 600 * np.sin(2 * math.pi * 0.02 * t) ** 2
        psi = np.cumsum(rate) * (t[1] - t[0]) * D2R
        return rot([0, 0, 1], psi), np.stack([0 * t, 0 * t, rate], 1)
    raise SystemExit(f"unknown motion {kind}")


def flip_starts(kind, period, duration, first, which):
    """Flip start times of platform 1 and 2 for the schedule kinds."""
    k = np.arange(first, duration, period)
    if kind == "paper":  # eq. (5): p2, p1, p2, p1, ...
        return k[1::2], k[0::2]
    if kind == "both":
        return k, k
    if kind == "one":  # only one platform flips
        return (k, np.array([])) if which == 1 else (np.array([]), k)
    if kind == "irregular":
        rng = np.random.default_rng(99)
        k = np.cumsum(rng.uniform(0.5, 2.0, size=int(duration / period * 2) + 2) * period) + first
        k = k[k < duration]
        return k[1::2], k[0::2]
    raise SystemExit(f"unknown schedule {kind}")


def sensor_output(rng, t, w_sensor, rate_hz, spec, bias0, rw):
    noise, lsb, fs, _, _ = spec
    n = len(t)
    walk = np.cumsum(rng.normal(0, rw / math.sqrt(rate_hz), (n, 3)), 0)
    bias = bias0[None] + walk
    y = w_sensor + bias + rng.normal(0, noise * math.sqrt(rate_hz), (n, 3))
    if lsb > 0:
        y = np.round(y * lsb) / lsb
    sat = np.abs(y) >= fs
    y = np.clip(y, -fs, fs)
    return y, bias, sat


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--out", required=True)
    p.add_argument("--sensor", default="mpu6050", choices=SENSORS)
    p.add_argument("--sensor2", default=None, choices=SENSORS)
    p.add_argument("--noise", type=float, help="override noise density deg/s/rtHz")
    p.add_argument("--fs1", type=float, help="override sensor 1 full scale deg/s")
    p.add_argument("--fs-key", type=float, help="gyro_full_scale_dps written in the header")
    p.add_argument("--rate", type=float, default=100.0)
    p.add_argument("--duration", type=float, default=300.0)
    p.add_argument("--period", type=float, default=20.0, help="s between flips")
    p.add_argument("--flip-s", type=float, default=1.0)
    p.add_argument("--amp", type=float, default=90.0, help="rest angle +-deg")
    p.add_argument("--schedule", default="paper", choices=["paper", "both", "one", "irregular"])
    p.add_argument("--which", type=int, default=2)
    p.add_argument("--hinge1", default="0,0,1")
    p.add_argument("--hinge2", default="1,0,0")
    p.add_argument("--motion", default="static")
    p.add_argument("--latitude", type=float, default=45.0)
    p.add_argument("--endstop", action="store_true", help="angles empty while moving")
    p.add_argument("--drop", type=float, default=0.0, help="fraction of rows dropped at random")
    p.add_argument("--gap", action="append", default=[], help="T:LEN seconds removed")
    p.add_argument("--dup", type=int, default=0, help="number of rows whose stamp repeats")
    p.add_argument("--no-truth", action="store_true")
    p.add_argument("--no-rate-key", action="store_true")
    p.add_argument("--seed", type=int, default=1)
    a = p.parse_args()
    rng = np.random.default_rng(a.seed)
    spec1 = list(SENSORS[a.sensor])
    spec2 = list(SENSORS[a.sensor2 or a.sensor])
    if a.noise is not None:
        spec1[0] = spec2[0] = a.noise
    if a.fs1 is not None:
        spec1[2] = a.fs1
    n = int(round(a.duration * a.rate))
    t = np.arange(n) / a.rate
    h1 = np.array([float(x) for x in a.hinge1.split(",")])
    h2 = np.array([float(x) for x in a.hinge2.split(",")])
    s1, s2 = flip_starts(a.schedule, a.period, a.duration, a.period, a.which)
    th1, dth1 = platform(t, np.asarray(s1, float), a.flip_s, a.amp)
    th2, dth2 = platform(t, np.asarray(s2, float), a.flip_s, a.amp)
    R_eb, w_rel = box_motion(t, a.motion, rng)
    lat = a.latitude * D2R
    w_earth_enu = EARTH_RATE_DPS * np.array([0, math.cos(lat), math.sin(lat)])
    w_body = w_rel + np.einsum("nji,j->ni", R_eb, w_earth_enu)  # R^T w_enu
    R1, R2 = rot(h1, th1 * D2R), rot(h2, th2 * D2R)
    w1 = np.einsum("nji,nj->ni", R1, w_body) + dth1[:, None] * (h1 / np.linalg.norm(h1))
    w2 = np.einsum("nji,nj->ni", R2, w_body) + dth2[:, None] * (h2 / np.linalg.norm(h2))
    b1 = rng.normal(0, spec1[3], 3)
    b2 = rng.normal(0, spec2[3], 3)
    y1, tb1, sat1 = sensor_output(rng, t, w1, a.rate, spec1, b1, spec1[4])
    y2, tb2, sat2 = sensor_output(rng, t, w2, a.rate, spec2, b2, spec2[4])
    q = mat_to_quat(R_eb)
    keep = np.ones(n, bool)
    if a.drop > 0:
        keep &= rng.uniform(size=n) >= a.drop
    for g in a.gap:
        g0, gl = (float(x) for x in g.split(":"))
        keep &= ~((t >= g0) & (t < g0 + gl))
    idx = np.nonzero(keep)[0]
    t_out = t[idx].copy()
    if a.dup > 0:
        pos = rng.choice(np.arange(10, len(idx) - 10), a.dup, replace=False)
        t_out[pos] = t_out[pos - 1]
    p1, p2 = th1.copy(), th2.copy()
    if a.endstop:
        p1[np.abs(np.abs(th1) - a.amp) > 1e-9] = np.nan
        p2[np.abs(np.abs(th2) - a.amp) > 1e-9] = np.nan
    cols = {"t": t_out}
    for i, ax in enumerate("xyz"):
        cols[f"gyro1_{ax}"] = y1[idx, i]
    for i, ax in enumerate("xyz"):
        cols[f"gyro2_{ax}"] = y2[idx, i]
    cols["plat1_deg"], cols["plat2_deg"] = p1[idx], p2[idx]
    for i, c in enumerate("wxyz"):
        cols[f"ref_q{c}"] = q[idx, i]
    if not a.no_truth:
        for s, tb in ((1, tb1), (2, tb2)):
            for i, ax in enumerate("xyz"):
                cols[f"true_bias{s}_{ax}"] = tb[idx, i]
        for i, ax in enumerate("xyz"):
            cols[f"true_rate_{ax}"] = w_body[idx, i]
        cols["true_plat1_deg"], cols["true_plat2_deg"] = th1[idx], th2[idx]
    with open(a.out, "w") as f:
        f.write("# format: driftless-log 1\n# complete: true\n")
        if not a.no_rate_key:
            f.write(f"# sample_rate_hz: {a.rate:g}\n")
        f.write(f"# latitude_deg: {a.latitude:g}\n")
        f.write(f"# hinge1_axis: {' '.join(str(float(x)) for x in h1)}\n")
        f.write(f"# hinge2_axis: {' '.join(str(float(x)) for x in h2)}\n")
        if a.fs_key:
            f.write(f"# gyro_full_scale_dps: {a.fs_key:g}\n")
        f.write(f"# source: probe_log.py sensor={a.sensor} seed={a.seed}\n")
        f.write(",".join(cols) + "\n")
        M = np.stack(list(cols.values()), 1)
        fmt = ["%.6f"] + ["%.7f"] * 6 + ["%.6f"] * 2 + ["%.10f"] * 4 + ["%.9f"] * (M.shape[1] - 13)
        np.savetxt(f, M, fmt=fmt, delimiter=",")
    print(f"{a.out}: {len(idx)} rows; bias1 {b1} bias2 {b2}; saturated rows s1 {int(sat1.any(1).sum())}"
          f" s2 {int(sat2.any(1).sum())}")


if __name__ == "__main__":
    main()
