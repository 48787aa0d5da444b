#!/usr/bin/python3
"""navgen.py -- an outsider's dual-gyro flip-box log generator (stop 27 probe).

Written from docs/log-format.md only (never from twin/ or estimator/): analytic box motion,
analytic flip profiles, own sensor presets and signal chain.  Writes a driftless-log 1 CSV.

Conventions (docs/log-format.md "Frame convention"):
  R_i = Rot(a_i, theta_i) = box-from-sensor;  y_i = R_i^T w_body + thetadot_i a_i  (+ errors)
  w_body = box inertial rate in box axes, Earth rate included (ENU Earth rate Om (0, cos lat, sin lat)).
  ref_q = q_enu_from_body (scalar first).  Specific force f = a - g, g = (0,0,-9.80665) ENU.
Box attitude: C_enu_from_body = Rz(psi) Rx(phi)  (yaw psi about Up, then roll phi about box x).
  body rate of the box w.r.t. ENU: w_nb = Rx(phi)^T (0,0,psidot) + (phidot,0,0).
"""
import argparse, math, sys
import numpy as np

G0 = 9.80665
OMEGA_E = 7.292115e-5 * 180 / math.pi  # deg/s

# name: (white noise deg/s/rtHz, bias instability deg/s, GM tau s, LSB per deg/s or 0, full scale dps)
PRESETS = {
    "bmi088":   (0.014, 2.0 / 3600 * 3, 300.0, 16.384, 2000.0),   # ~6 deg/h instability
    "adis16470": (0.34 / 60.0, 8.0 / 3600, 200.0, 10.0, 2000.0),  # ARW 0.34 deg/rt h
    "fog":      (0.002, 0.05 / 3600, 1000.0, 0.0, 500.0),
    "noisy":    (0.05, 0.05, 100.0, 65.5, 500.0),                  # 10x MPU6050
    "mpu6050":  (0.005, 0.01, 100.0, 131.0, 250.0),
}


def rot(axis, ang_rad):
    """Rotation matrices about a unit axis, for an array of angles: shape (n,3,3)."""
    a = np.asarray(axis, float); a = a / np.linalg.norm(a)
    c = np.cos(ang_rad); s = np.sin(ang_rad); C = 1 - c
    x, y, z = a
    R = np.empty((len(ang_rad), 3, 3))
    R[:, 0, 0] = c + x * x * C; R[:, 0, 1] = x * y * C - z * s; R[:, 0, 2] = x * z * C + y * s
    R[:, 1, 0] = y * x * C + z * s; R[:, 1, 1] = c + y * y * C; R[:, 1, 2] = y * z * C - x * s
    R[:, 2, 0] = z * x * C - y * s; R[:, 2, 1] = z * y * C + x * s; R[:, 2, 2] = c + z * z * C
    return R


def small_rot(rng, sigma_deg):
    v = rng.normal(0, math.radians(sigma_deg), 3)
    th = np.linalg.norm(v)
    if th == 0:
        return np.eye(3)
    return rot(v / th, np.array([th]))[0]


class Schedule:
    """Piecewise flips: list of (t_start, duration, platform, from_deg, to_deg)."""

    def __init__(self, args, rng):
        self.flips = []
        a = args.angle
        pos = [a, a]
        t = args.first_rest
        # eq.(5) style: (+,+) -> (+,-) -> (-,-) -> (-,+): platform 2, then 1, alternating
        who = 1 if args.order == "p2first" else 0
        k = 0
        while t < args.duration + args.t0 + 10:
            if args.order == "both":
                plats = [0, 1]
            elif args.order == "only1":
                plats = [0]
            else:
                plats = [who]
            for p in plats:
                stuck = args.stick is not None and p == 1 and t >= args.stick
                new = pos[p] + 180.0 if args.oneway else -pos[p]
                self.flips.append((t, args.flip_s, p, pos[p], new, stuck))
                pos[p] = new
            who = 1 - who
            k += 1
            rest = args.rest
            if args.rest_max > args.rest:
                rest = rng.uniform(args.rest, args.rest_max)
            t += args.flip_s + rest

    def angles(self, t, p):
        """true angle (deg), rate (deg/s), reported angle for platform p at times t."""
        ang = np.full_like(t, self.start(p)); rate = np.zeros_like(t)
        rep = np.full_like(t, self.start(p)); moving = np.zeros(t.shape, bool)
        for (ts, d, pp, a0, a1, stuck) in self.flips:
            if pp != p:
                continue
            after = t >= ts + d
            during = (t >= ts) & (t < ts + d)
            s = (t[during] - ts) / d
            if not stuck:
                ang[after] = a1
                ang[during] = a0 + (a1 - a0) * (1 - np.cos(np.pi * s)) / 2
                rate[during] = (a1 - a0) * np.pi / (2 * d) * np.sin(np.pi * s)
            rep[after] = a1  # reported: commanded/end-stop angle
            rep[during] = a0 + (a1 - a0) * (1 - np.cos(np.pi * s)) / 2
            moving |= during
        return ang, rate, rep, moving

    def start(self, p):
        return self.args_angle

    args_angle = 90.0


def box_motion(t, args):
    """psi, phi (rad), their rates (rad/s), body-frame linear accel (m/s^2), all arrays."""
    n = len(t)
    psi = np.zeros(n); psid = np.zeros(n); phi = np.zeros(n); phid = np.zeros(n)
    acc = np.zeros((n, 3))
    if args.motion == "car":
        # yaw: 90-deg turns, 6 s each, every 40 s; forward accel bursts 0.3 g
        per = 40.0; dur = 6.0
        tk = np.mod(t, per); k = np.floor(t / per)
        during = tk < dur
        s = tk / dur
        base = k * math.pi / 2 * np.where(np.mod(k, 2) == 0, 1, 1)
        psi = base + np.where(during, math.pi / 2 * (s - np.sin(2 * np.pi * s) / (2 * np.pi)), math.pi / 2)
        psid = np.where(during, math.pi / 2 / dur * (1 - np.cos(2 * np.pi * s)), 0.0)
        v = 15.0
        acc[:, 1] = v * psid                                   # centripetal (left turn)
        acc[:, 0] = 0.3 * G0 * np.sin(2 * np.pi * t / 13.0)    # speeding up / braking
        acc[:, 2] = 0.05 * G0 * np.sin(2 * np.pi * t * 1.7)   # road bumps
    elif args.motion == "slowyaw":
        w = math.radians(args.yaw_rate)
        psi = w * t; psid = np.full(n, w)
    elif args.motion == "shake":
        # a box that holds its pose but shakes about up: a zero-mean yaw rate (a servo's hold, a
        # mount's vibration), the angle 0 .. 2 A / (2 pi f) and back every period
        A = math.radians(args.shake_dps); w = 2 * math.pi * args.shake_hz
        psi = A / w * (1 - np.cos(w * t)); psid = A * np.sin(w * t)
    elif args.motion == "rock":
        A = math.radians(20); w = 2 * math.pi / 17.0
        phi = A * np.sin(w * t); phid = A * w * np.cos(w * t)
        psi = 0.3 * np.sin(2 * np.pi * t / 61.0); psid = 0.3 * 2 * np.pi / 61.0 * np.cos(2 * np.pi * t / 61.0)
    return psi, psid, phi, phid, acc


def truth(t, args, sched):
    psi, psid, phi, phid, acc = box_motion(t, args)
    n = len(t)
    lat = math.radians(args.lat)
    w_ie = np.array([0.0, math.cos(lat), math.sin(lat)]) * OMEGA_E  # deg/s ENU
    Rz = rot([0, 0, 1], psi); Rx = rot([1, 0, 0], phi)
    C = Rz @ Rx  # enu from body
    w_nb = np.einsum("nji,j->ni", Rx, np.array([0, 0, 1.0])) * psid[:, None] + np.outer(phid, [1, 0, 0])
    w_body = np.degrees(w_nb) + np.einsum("nji,j->ni", C, w_ie)
    g_body = np.einsum("nji,j->ni", C, np.array([0, 0, -G0]))
    f_body = acc - g_body
    return C, w_body, f_body


def quat_from_C(C):
    tr = C[:, 0, 0] + C[:, 1, 1] + C[:, 2, 2]
    qw = np.sqrt(np.maximum(0, 1 + tr)) / 2
    qx = np.copysign(np.sqrt(np.maximum(0, 1 + C[:, 0, 0] - C[:, 1, 1] - C[:, 2, 2])) / 2, C[:, 2, 1] - C[:, 1, 2])
    qy = np.copysign(np.sqrt(np.maximum(0, 1 - C[:, 0, 0] + C[:, 1, 1] - C[:, 2, 2])) / 2, C[:, 0, 2] - C[:, 2, 0])
    qz = np.copysign(np.sqrt(np.maximum(0, 1 - C[:, 0, 0] - C[:, 1, 1] + C[:, 2, 2])) / 2, C[:, 1, 0] - C[:, 0, 1])
    return np.stack([qw, qx, qy, qz], 1)


def format_rows(args, ts, keep, ys, reps, q, fs, temps, biases):
    """A chunk's CSV rows as one text. A row whose stamp (rounded to 1e-6 of its unit) does not
    increase on the previous kept row is dropped. One %-format per row for its numbers: the same
    digits as a format per number (both are Python's correctly rounded fixed notation), at a
    third of the time; an empty platform angle (NaN) is an empty field."""
    tscale = {"s": 1, "ms": 1e3, "us": 1e6, "ns": 1e9}[args.tunit]
    kept = np.nonzero(keep)[0]
    sel, stamps, prev = [], [], -1e300
    for k, tv in zip(kept.tolist(), np.round(ts[kept] * tscale, 6).tolist()):
        if tv <= prev:
            continue
        prev = tv
        sel.append(k)
        stamps.append(tv)
    head = np.column_stack([np.array(stamps, dtype=float), ys[0][sel], ys[1][sel]]).tolist()
    head_fmt = ("%.6f" if args.tunit == "s" else "%.0f") + ",%.7f" * 6
    angles = [["" if math.isnan(v) else "%.6f" % v for v in reps[j][sel].tolist()] for j in range(2)]
    parts = []
    if not args.no_ref:
        parts.append((q[sel], "%.10f"))
    if not args.no_accel:
        parts += [(fs[0][sel], "%.5f"), (fs[1][sel], "%.5f")]
    if args.temp:
        parts += [(temps[0][sel][:, None], "%.3f"), (temps[1][sel][:, None], "%.3f")]
    if not args.no_truth:
        parts += [(biases[0][sel], "%.9f"), (biases[1][sel], "%.9f")]
    tail_fmt = "".join(("," + f) * a.shape[1] for a, f in parts)
    tail = np.column_stack([a for a, _ in parts]).tolist() if parts else [[]] * len(sel)
    lines = [head_fmt % tuple(h) + "," + a1 + "," + a2 + tail_fmt % tuple(r)
             for h, a1, a2, r in zip(head, angles[0], angles[1], tail)]
    return "\n".join(lines) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", required=True)
    ap.add_argument("--duration", type=float, default=600.0, help="s")
    ap.add_argument("--rate", type=float, default=100.0, help="Hz")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--sensor", default="bmi088", choices=sorted(PRESETS))
    ap.add_argument("--sensor2", default=None, choices=sorted(PRESETS), help="default: same as --sensor")
    ap.add_argument("--noise", type=float, default=None, help="override white noise deg/s/rtHz (both)")
    ap.add_argument("--bias", type=float, default=1.0, help="turn-on bias sigma deg/s")
    ap.add_argument("--scale", type=float, default=0.0, help="scale error sigma (fraction, per axis)")
    ap.add_argument("--misalign", type=float, default=0.0, help="misalignment sigma deg")
    ap.add_argument("--gsens", type=float, default=0.0, help="g-sensitivity element sigma deg/s/g")
    ap.add_argument("--lat", type=float, default=47.4)
    ap.add_argument("--hinge1", default="0 0 1")
    ap.add_argument("--hinge2", default="1 0 0")
    ap.add_argument("--angle", type=float, default=90.0, help="rest angles +-angle deg")
    ap.add_argument("--flip-s", type=float, default=1.0)
    ap.add_argument("--rest", type=float, default=20.0)
    ap.add_argument("--rest-max", type=float, default=0.0, help=">rest: uniform random rests")
    ap.add_argument("--first-rest", type=float, default=15.0)
    ap.add_argument("--order", default="p2first", choices=["p2first", "p1first", "both", "only1"])
    ap.add_argument("--stick", type=float, default=None, help="platform 2 sticks from t (s)")
    ap.add_argument("--stick-report", default="command", choices=["command", "readback"])
    ap.add_argument("--endstop", action="store_true", help="angles empty while moving")
    ap.add_argument("--motion", default="static", choices=["static", "car", "rock", "slowyaw", "shake"])
    ap.add_argument("--lowpass", type=float, default=0.0, help="1st-order low-pass Hz (both), 0 = none")
    ap.add_argument("--lowpass2", type=float, default=None, help="sensor 2 low-pass Hz (default = --lowpass)")
    ap.add_argument("--delay2", type=float, default=0.0, help="sensor 2 reads the truth this late (s)")
    ap.add_argument("--jitter", type=float, default=0.0, help="stamp jitter sigma s (stamps only)")
    ap.add_argument("--gap", action="append", default=[], help="T:LEN drop rows")
    ap.add_argument("--t0", type=float, default=0.0, help="log starts at this time of the schedule")
    ap.add_argument("--tunit", default="s", choices=["s", "ms", "us", "ns"])
    ap.add_argument("--no-accel", action="store_true")
    ap.add_argument("--no-ref", action="store_true")
    ap.add_argument("--no-truth", action="store_true")
    ap.add_argument("--no-rate-key", action="store_true")
    ap.add_argument("--fs-key", action="store_true", help="write gyro1/2_full_scale_dps")
    ap.add_argument("--temp", action="store_true", help="temperature columns with a warm-up and tempco")
    ap.add_argument("--angle-offset", type=float, default=0.0, help="rests at offset +- angle (deg)")
    ap.add_argument("--step", default=None, help="T:SENSOR(1|2):AXIS(0-2):DPS bias step")
    ap.add_argument("--oneway", action="store_true", help="every flip turns +180 (reported angle wrapped to [-180,180))")
    ap.add_argument("--yaw-rate", type=float, default=0.05, help="slowyaw: deg/s")
    ap.add_argument("--shake-dps", type=float, default=0.2, help="shake: yaw rate amplitude deg/s")
    ap.add_argument("--shake-hz", type=float, default=2.0, help="shake: frequency Hz")
    ap.add_argument("--chunk", type=float, default=600.0)
    ap.add_argument("--truth-out", default=None, help="write the constant truth (json)")
    args = ap.parse_args()
    rng = np.random.default_rng(args.seed)
    Schedule.args_angle = args.angle
    sched = Schedule(args, rng)
    s2 = args.sensor2 or args.sensor
    pre = [PRESETS[args.sensor], PRESETS[s2]]
    hinges = [np.array([float(v) for v in args.hinge1.split()]), np.array([float(v) for v in args.hinge2.split()])]
    hinges = [h / np.linalg.norm(h) for h in hinges]
    b0 = [rng.normal(0, args.bias, 3) for _ in range(2)]
    Es = [np.diag(rng.normal(0, args.scale, 3)) if args.scale else np.zeros((3, 3)) for _ in range(2)]
    Ms = [small_rot(rng, args.misalign) if args.misalign else np.eye(3) for _ in range(2)]
    Gs = [rng.normal(0, args.gsens, (3, 3)) for _ in range(2)]
    tc = [rng.normal(0, 0.02, 3) for _ in range(2)]
    # effective: y = (I+E) Mis^T w + b + G f/g
    A = [(np.eye(3) + Es[i]) @ Ms[i].T for i in range(2)]
    noise = [args.noise if args.noise is not None else pre[i][0] for i in range(2)]
    gm = [np.zeros(3), np.zeros(3)]
    lp_state = [None, None]
    lpf = [args.lowpass, args.lowpass if args.lowpass2 is None else args.lowpass2]
    dt = 1.0 / args.rate
    nt = int(round(args.duration * args.rate))
    gaps = [tuple(float(x) for x in g.split(":")) for g in args.gap]

    out = open(args.out, "w")
    out.write("# format: driftless-log 1\n# complete: true\n")
    if not args.no_rate_key:
        out.write(f"# sample_rate_hz: {args.rate:g}\n")
    out.write(f"# latitude_deg: {args.lat:g}\n")
    out.write(f"# hinge1_axis: {args.hinge1}\n# hinge2_axis: {args.hinge2}\n")
    if args.fs_key:
        out.write(f"# gyro1_full_scale_dps: {pre[0][4]:g}\n# gyro2_full_scale_dps: {pre[1][4]:g}\n")
    out.write(f"# source: navgen.py (outsider) sensor={args.sensor}/{s2} seed={args.seed}\n")
    cols = ["t", "gyro1_x", "gyro1_y", "gyro1_z", "gyro2_x", "gyro2_y", "gyro2_z", "plat1_deg", "plat2_deg"]
    if not args.no_ref:
        cols += ["ref_qw", "ref_qx", "ref_qy", "ref_qz"]
    if not args.no_accel:
        cols += [f"accel{i}_{c}" for i in (1, 2) for c in "xyz"]
    if args.temp:
        cols += ["temp1", "temp2"]
    if not args.no_truth:
        cols += [f"true_bias{i}_{c}" for i in (1, 2) for c in "xyz"]
    out.write(",".join(cols) + "\n")
    nchunk = int(round(args.chunk * args.rate))
    last_bias = None
    for c0 in range(0, nt, nchunk):
        idx = np.arange(c0, min(nt, c0 + nchunk))
        t = args.t0 + idx * dt
        n = len(t)
        ys = []; fs = []; biases = []; reps = []; temps = []
        for i in range(2):
            ti = t - (args.delay2 if i == 1 else 0.0)
            C, w_body, f_body = truth(ti, args, sched)
            ang, rate, rep, moving = sched.angles(ti, i)
            if args.stick is not None and i == 1 and args.stick_report == "readback":
                rep = ang
            ang = ang + args.angle_offset; rep = rep + args.angle_offset
            if args.oneway:
                rep = np.mod(rep + 180.0, 360.0) - 180.0
            R = rot(hinges[i], np.radians(ang))
            w_s = np.einsum("nji,nj->ni", R, w_body) + rate[:, None] * hinges[i][None, :]
            f_s = np.einsum("nji,nj->ni", R, f_body)
            # GM bias instability at 1 Hz, interpolated
            sig_b, tau = pre[i][1], pre[i][2]
            nsec = int(math.ceil(n * dt)) + 2
            a = math.exp(-1.0 / tau)
            gmv = np.empty((nsec, 3)); x = gm[i]
            for k in range(nsec):
                gmv[k] = x
                x = a * x + rng.normal(0, sig_b * math.sqrt(1 - a * a), 3)
            gm[i] = gmv[int(n * dt)] if int(n * dt) < nsec else x
            bg = np.array([np.interp((t - t[0]), np.arange(nsec), gmv[:, j]) for j in range(3)]).T
            bias = b0[i][None, :] + bg
            if args.temp:
                T = 25 + 3 * (1 - np.exp(-(t) / 300.0)) + 0.2 * i
                bias = bias + (T[:, None] - 25) * tc[i][None, :]
                temps.append(T)
            if args.step:
                st_t, st_s, st_a, st_v = args.step.split(":")
                if int(st_s) == i + 1:
                    bias = bias.copy(); bias[:, int(st_a)] += np.where(t >= float(st_t), float(st_v), 0.0)
            y = w_s @ A[i].T + bias + f_s @ Gs[i].T / G0
            y = y + rng.normal(0, noise[i] * math.sqrt(args.rate), (n, 3))
            if lpf[i] > 0:
                al = 1 - math.exp(-2 * math.pi * lpf[i] * dt)
                st = y[0].copy() if lp_state[i] is None else lp_state[i]
                yf = np.empty_like(y)
                for k in range(n):
                    st = st + al * (y[k] - st)
                    yf[k] = st
                lp_state[i] = st
                y = yf
            lsb = pre[i][3]
            if lsb > 0:
                y = np.round(y * lsb) / lsb
            fsd = pre[i][4]
            y = np.clip(y, -fsd, fsd)
            repc = rep.copy()
            if args.endstop:
                repc[moving] = np.nan
            ys.append(y); fs.append(f_s); biases.append(bias); reps.append(repc)
        C, w_body, f_body = truth(t, args, sched)
        q = quat_from_C(C)
        ts = t - args.t0
        if args.jitter > 0:
            ts = ts + rng.normal(0, args.jitter, n)
            ts = np.maximum.accumulate(ts)  # keep increasing-ish; duplicates fixed below
        keep = np.ones(n, bool)
        for (g0, gl) in gaps:
            keep &= ~((ts >= g0) & (ts < g0 + gl))
        out.write(format_rows(args, ts, keep, ys, reps, q, fs, temps, biases))
        last_bias = [biases[0][-1], biases[1][-1]]
    out.close()
    import json
    info = {"b_final": [list(map(float, last_bias[0])), list(map(float, last_bias[1]))],
            "E": [Es[i].tolist() for i in range(2)], "Mis": [Ms[i].tolist() for i in range(2)],
            "G": [Gs[i].tolist() for i in range(2)], "noise": noise}
    if args.truth_out:
        json.dump(info, open(args.truth_out, "w"), indent=1)
    print(f"wrote {args.out}: {nt} rows; final bias s1 {np.round(last_bias[0], 4)} s2 {np.round(last_bias[1], 4)}",
          file=sys.stderr)


if __name__ == "__main__":
    main()
