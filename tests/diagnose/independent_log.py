#!/usr/bin/python3
"""An independent generator of dual-gyro logs in the documented format (docs/log-format.md).

Written apart from twin/: its own quaternions, kinematics, sensor errors, low-pass, sampling and
ADC, with numpy only. It varies what real sources vary: no DLPF or another DLPF (run at an
internal 1 kHz rate, then sampled), noise 0.5-3x the MPU6050's, several motion profiles,
50/100/200 Hz output, either sensor sampling late, a box time offset, and one or more physical
effects planted at datasheet magnitude. The compare/diagnose acceptance tests run it
(tests/diagnose/slow_test_independent_logs.cpp).

  /usr/bin/python3 independent_log.py --out log.csv --seed 3 --rate 100 --duration 180 \
      --motion pan_tilt --noise-scale 1.5 --dlpf none --plant scale:1:x:3 --lag 2:0.015

With --single it writes the single-sensor form (docs/log-format.md, 'sensors: 1'): one IMU fixed
to the moving body (no platforms, no flips) against the body's reference attitude ref_q, as a
motion-capture recording gives it; --accel adds its accelerometer (accel1_*, with noise).

Planted effects (repeatable --plant): scale:S:AX:PCT, misalign:S:ROW:COL:PCT,
gsens:S:ROW:COL:DPS_PER_G, mount:S:AX:DEG, stop:P:minus|plus:DEG, tempco:S:AX:DPS_PER_DEGC,
quant:LSB_PER_DPS. Units: deg/s, deg, s, %, degC.
"""
import argparse
import math
import sys

import numpy as np

G = 9.80665                       # m/s^2
EARTH_RATE = 7.292115e-5          # rad/s
D2R = math.pi / 180.0
AXES = {"x": 0, "y": 1, "z": 2}
# MPU6050 register 26 gyro columns: (bandwidth Hz, delay s) for DLPF_CFG 0..6
DLPF = [(256.0, 0.98e-3), (188.0, 1.9e-3), (98.0, 2.8e-3), (42.0, 4.8e-3), (20.0, 8.3e-3), (10.0, 13.4e-3), (5.0, 18.6e-3)]
INTERNAL_HZ = 1000.0


# ---- rotations (own code: quaternions w, x, y, z; matrices act on column vectors) ----

def quat_mul(a, b):
    w1, x1, y1, z1 = a
    w2, x2, y2, z2 = b
    return np.array([w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
                     w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
                     w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
                     w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2])


def rot_axis(axis, angle_rad):
    """Rotation matrices about a unit axis (Rodrigues), vectorised over angle_rad."""
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    ang = np.atleast_1d(angle_rad)
    s, c = np.sin(ang)[:, None, None], np.cos(ang)[:, None, None]
    return np.eye(3)[None] + s * k[None] + (1 - c) * (k @ k)[None]


def small_rotation(rotvec_rad):
    """exp([theta]x) of a rotation vector."""
    th = np.linalg.norm(rotvec_rad)
    if th == 0:
        return np.eye(3)
    return rot_axis(rotvec_rad / th, th)[0]


# ---- motion of the box: yaw (pan) and pitch (tilt) as smooth functions of time ----

def smooth_moves(t, rng, amplitude_deg, move_s, dwell_s):
    """Point-to-point moves with a raised-cosine rate (continuous acceleration) and dwells."""
    angle = np.zeros_like(t)
    rate = np.zeros_like(t)
    t0, a0 = 0.0, 0.0
    while t0 < t[-1]:
        dwell = rng.uniform(*dwell_s)
        t0 += dwell
        T = rng.uniform(*move_s)
        a1 = rng.uniform(-amplitude_deg, amplitude_deg)
        m = (t >= t0) & (t < t0 + T)
        u = (t[m] - t0) / T
        angle[m] = a0 + (a1 - a0) * (u - np.sin(2 * math.pi * u) / (2 * math.pi))
        rate[m] = (a1 - a0) / T * (1 - np.cos(2 * math.pi * u))
        after = t >= t0 + T
        angle[after] = a1
        t0, a0 = t0 + T, a1
    return angle * D2R, rate * D2R


def box_motion(t, kind, rng):
    """yaw, pitch (rad) and their rates (rad/s)."""
    z = np.zeros_like(t)
    if kind == "static":
        return z, z, z, z
    if kind == "pan_tilt":
        yaw, dyaw = smooth_moves(t, rng, 80.0, (1.5, 4.0), (0.5, 3.0))
        pitch, dpitch = smooth_moves(t, rng, 35.0, (1.5, 4.0), (0.5, 3.0))
        return yaw, dyaw, pitch, dpitch
    if kind == "sweep":
        f1, f2 = rng.uniform(0.04, 0.12), rng.uniform(0.07, 0.2)
        a1, a2 = 60 * D2R, 25 * D2R
        return (a1 * np.sin(2 * math.pi * f1 * t), a1 * 2 * math.pi * f1 * np.cos(2 * math.pi * f1 * t),
                a2 * np.sin(2 * math.pi * f2 * t), a2 * 2 * math.pi * f2 * np.cos(2 * math.pi * f2 * t))
    if kind == "wobble":
        yaw, dyaw, pitch, dpitch = z.copy(), z.copy(), z.copy(), z.copy()
        for _ in range(3):
            f, a, ph = rng.uniform(0.3, 1.5), rng.uniform(2, 6) * D2R, rng.uniform(0, 2 * math.pi)
            yaw += a * np.sin(2 * math.pi * f * t + ph)
            dyaw += a * 2 * math.pi * f * np.cos(2 * math.pi * f * t + ph)
            f, a, ph = rng.uniform(0.3, 1.5), rng.uniform(2, 6) * D2R, rng.uniform(0, 2 * math.pi)
            pitch += a * np.sin(2 * math.pi * f * t + ph)
            dpitch += a * 2 * math.pi * f * np.cos(2 * math.pi * f * t + ph)
        return yaw, dyaw, pitch, dpitch
    raise SystemExit(f"unknown motion '{kind}'")


def flips(t, period_s, flip_s, phase_s):
    """A platform flipping between +90 and -90 deg every period_s (raised-cosine, flip_s long):
    true angle (deg, without stop errors), rate (deg/s), moving flag, side at rest (+1/-1)."""
    n_flip = np.floor((t - phase_s) / period_s).astype(int)
    n_flip[t < phase_s] = -1
    u = np.clip((t - phase_s - n_flip * period_s) / flip_s, 0, 1)
    start = np.where(n_flip % 2 == 0, 90.0, -90.0)
    end = -start
    moving = (n_flip >= 0) & (u < 1)
    s = u - np.sin(2 * math.pi * u) / (2 * math.pi)
    ds = (1 - np.cos(2 * math.pi * u)) / flip_s
    angle = np.where(n_flip >= 0, start + (end - start) * s, 90.0)
    rate = np.where(moving, (end - start) * ds, 0.0)
    side = np.where(n_flip < 0, 1.0, np.sign(end))
    return angle, rate, moving, side


# ---- the sensor: errors, low-pass at the internal rate, sampling, noise, ADC ----

def first_order(x, a):
    """y_k = a y_{k-1} + (1 - a) x_k along axis 0, starting in steady state, in blocks of 256
    (y = T x + a^(i+1) y_prev with T lower triangular)."""
    if a == 0.0:
        return x.copy()
    M = 256
    i = np.arange(M)
    T = np.tril((1 - a) * a ** (i[:, None] - i[None, :]).clip(min=0))
    T[np.triu_indices(M, 1)] = 0.0
    pw = a ** (i + 1)
    y = np.empty_like(x)
    prev = x[0]
    for s in range(0, len(x), M):
        xb = x[s:s + M]
        m = len(xb)
        yb = T[:m, :m] @ xb + pw[:m, None] * prev[None, :]
        y[s:s + m] = yb
        prev = yb[-1]
    return y


def delay_signal(x, delay_samples):
    """x delayed by a (fractional) number of samples, linear interpolation, first value held."""
    n = len(x)
    src = np.arange(n) - delay_samples
    src = np.clip(src, 0, n - 1)
    i0 = np.floor(src).astype(int)
    i1 = np.minimum(i0 + 1, n - 1)
    u = (src - i0)[:, None]
    return (1 - u) * x[i0] + u * x[i1]


def sample_at(x_int, t_int, t_out):
    """Values of an internal-rate series at output instants (linear interpolation)."""
    return np.stack([np.interp(t_out, t_int, x_int[:, j]) for j in range(3)], axis=1)


def parse_dlpf(text):
    if text == "none":
        return None
    if text.startswith("cfg:"):
        return DLPF[int(text[4:])]
    if text.startswith("custom:"):
        _, bw, d = text.split(":")
        return float(bw), float(d)
    raise SystemExit(f"unknown --dlpf '{text}' (none, cfg:N, custom:BW_HZ:DELAY_S)")


def sensor_errors(plants, s):
    """(I + M) diag(1 + scale), G (deg/s per g), mounting rotation, bias tempco per axis."""
    scale = np.zeros(3)
    M = np.zeros((3, 3))
    Gs = np.zeros((3, 3))
    mount = np.zeros(3)
    tempco = np.zeros(3)
    for p in plants:
        f = p.split(":")
        kind = f[0]
        if kind in ("stop", "quant") or int(f[1]) != s + 1:
            continue
        if kind == "scale":
            scale[AXES[f[2]]] += float(f[3]) / 100
        elif kind == "misalign":
            M[AXES[f[2]], AXES[f[3]]] += float(f[4]) / 100
        elif kind == "gsens":
            Gs[AXES[f[2]], AXES[f[3]]] += float(f[4])
        elif kind == "mount":
            mount[AXES[f[2]]] += float(f[3]) * D2R
        elif kind == "tempco":
            tempco[AXES[f[2]]] += float(f[3])
        else:
            raise SystemExit(f"unknown --plant '{p}'")
    return (np.eye(3) + M) @ np.diag(1 + scale), Gs, small_rotation(mount), tempco


def rows_text(parts):
    """The rows of `parts` ((array of n rows, %-format of each of its columns), ...) side by side
    as CSV text, one %-format per row: the same digits as a format per number (both are Python's
    correctly rounded fixed notation), in about half the time."""
    fmt = ",".join(",".join([f] * a.shape[1]) for a, f in parts)
    return "".join(fmt % tuple(r) + "\n" for r in np.column_stack([a for a, _ in parts]).tolist())


def write_single(args, t_out, gyro, accel, q_out, temp_out):
    """The single-sensor form: t, gyro1_*, ref_q, [accel1_*], [temp1]."""
    with open(args.out, "w") as f:
        f.write("# format: driftless-log 1\n# complete: true\n# sensors: 1\n")
        f.write(f"# sample_rate_hz: {args.rate:g}\n# latitude_deg: {args.latitude:g}\n")
        f.write("# source: independent generator (tests/diagnose), one IMU against motion capture\n")
        f.write(f"# seed: {args.seed}\n")
        cols = "t,gyro1_x,gyro1_y,gyro1_z,ref_qw,ref_qx,ref_qy,ref_qz"
        cols += ",accel1_x,accel1_y,accel1_z" if args.accel else ""
        f.write(cols + (",temp1\n" if args.temperature else "\n"))
        parts = [(t_out[:, None], "%.6f"), (gyro, "%.7f"), (q_out, "%.10f")]
        if args.accel:
            parts.append((accel, "%.5f"))
        if args.temperature:
            parts.append((temp_out[:, None], "%.3f"))
        f.write(rows_text(parts))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", required=True)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--rate", type=float, default=100.0, help="output rate, Hz (50, 100, 200, ...)")
    ap.add_argument("--duration", type=float, default=180.0, help="s")
    ap.add_argument("--motion", default="pan_tilt", help="pan_tilt, sweep, wobble, static")
    ap.add_argument("--noise-scale", type=float, default=1.0, help="x the MPU6050's 0.005 deg/s/rtHz")
    ap.add_argument("--dlpf", default="none", help="none, cfg:N (MPU6050 DLPF_CFG), custom:BW_HZ:DELAY_S")
    ap.add_argument("--lag", action="append", default=[], help="S:SECONDS: sensor S samples late")
    ap.add_argument("--time-offset", type=float, default=0.0, help="s: both sensors sample this long before the stamp")
    ap.add_argument("--plant", action="append", default=[])
    ap.add_argument("--flip-period", type=float, default=10.0, help="s between flips of each platform")
    ap.add_argument("--latitude", type=float, default=48.1)
    ap.add_argument("--temperature", action="store_true", help="log temp1/temp2 (a 6 degC warm-up)")
    ap.add_argument("--single", action="store_true", help="one IMU fixed to the body, no platforms ('sensors: 1')")
    ap.add_argument("--accel", action="store_true", help="log the accelerometer (accel1_*, m/s^2; --single only)")
    args = ap.parse_args()
    rng = np.random.default_rng(args.seed)

    fs = args.rate
    step = int(round(INTERNAL_HZ / fs))
    if abs(step * fs - INTERNAL_HZ) > 1e-9:
        raise SystemExit("--rate must divide 1000 Hz")
    n_out = int(round(args.duration * fs))
    t_out = np.arange(n_out) / fs
    pad = 0.2  # s of internal history before the first output (filters and lags settle)
    t_int = np.arange(-int(pad * INTERNAL_HZ), n_out * step + step) / INTERNAL_HZ

    # box: attitude, rate relative to ENU plus the Earth rate, specific force (static position)
    yaw, dyaw, pitch, dpitch = box_motion(t_int, args.motion, rng)
    R_eb = rot_axis([0, 0, 1], yaw) @ rot_axis([0, 1, 0], pitch)
    Ry = rot_axis([0, 1, 0], pitch)
    w_body = np.einsum("nji,nj->ni", Ry, np.stack([0 * yaw, 0 * yaw, dyaw], 1)) + np.stack([0 * yaw, dpitch, 0 * yaw], 1)
    lat = args.latitude * D2R
    earth_enu = EARTH_RATE * np.array([0.0, math.cos(lat), math.sin(lat)])
    w_body += np.einsum("nji,j->ni", R_eb, earth_enu)
    f_body = np.einsum("nji,j->ni", R_eb, np.array([0.0, 0.0, G]))

    # platforms: hinge a1 = z, a2 = x; stop errors planted on the true resting angle
    hinges = [np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0])]
    stop_err = np.zeros((2, 2))  # [platform][0: at -stop, 1: at +stop], deg
    for p in args.plant:
        f = p.split(":")
        if f[0] == "stop":
            stop_err[int(f[1]) - 1, 1 if f[2] == "plus" else 0] += float(f[3])
    plat_true, plat_rate, plat_moving, plat_side = [], [], [], []
    for i in range(2):
        ang, rate, moving, side = flips(t_int, args.flip_period, 1.0, 2.0 + i * args.flip_period / 2)
        if args.single:  # the IMU is fixed to the body: no platform
            z = np.zeros_like(t_int)
            ang, rate, moving, side = z, z, z.astype(bool), z
        ang = ang + np.where(moving, 0.0, np.where(side > 0, stop_err[i, 1], stop_err[i, 0]))
        plat_true.append(ang), plat_rate.append(rate), plat_moving.append(moving), plat_side.append(side)

    temp = 25.0 + 6.0 * (1 - np.exp(-(t_int - t_int[0]) / 120.0)) if args.temperature else np.full_like(t_int, 25.0)

    lags = [0.0, 0.0]
    for spec in args.lag:
        s, v = spec.split(":")
        lags[int(s) - 1] += float(v)
    dlpf = parse_dlpf(args.dlpf)
    lsb = 1.0 / 131.0
    for p in args.plant:
        if p.startswith("quant:"):
            lsb = 1.0 / float(p.split(":")[1])
    N = 0.005 * args.noise_scale

    gyro, accel = [], []
    for i in range(1 if args.single else 2):
        R_i = rot_axis(hinges[i], plat_true[i] * D2R)
        w_s = np.einsum("nji,nj->ni", R_i, w_body) + (plat_rate[i] * D2R)[:, None] * hinges[i][None, :]
        f_s = np.einsum("nji,nj->ni", R_i, f_body)
        CM, Gs, R_mount, tempco = sensor_errors(args.plant, i)
        y = (np.einsum("ij,nj->ni", CM @ R_mount.T, w_s) / D2R + np.einsum("ij,nj->ni", Gs, f_s / G)
             + tempco[None, :] * (temp - 25.0)[:, None])
        bias = rng.normal(0.0, 2.0, 3)[None, :] + np.cumsum(rng.normal(0.0, 2e-5 / math.sqrt(INTERNAL_HZ), (len(t_int), 3)), 0)
        y += bias
        if dlpf is not None:
            bw, delay = dlpf
            a = math.exp(-2 * math.pi * bw / INTERNAL_HZ)
            noise = rng.normal(0.0, N * math.sqrt(INTERNAL_HZ), y.shape)
            pole_delay = a / (1 - a) / INTERNAL_HZ
            y = delay_signal(first_order(y + noise, a), max(0.0, delay - pole_delay) * INTERNAL_HZ)
        # the sensor samples at t - lag - offset
        yo = sample_at(y, t_int, t_out - lags[i] - args.time_offset)
        if dlpf is None:
            yo += rng.normal(0.0, N * math.sqrt(fs), yo.shape)
        yo = np.clip(np.round(yo / lsb) * lsb, -250.0, 250.0)
        gyro.append(yo)
        # accelerometer: specific force in sensor axes, sampled with the gyro, 0.004 m/s^2 noise
        fo = sample_at(f_s, t_int, t_out - lags[i] - args.time_offset)
        accel.append(fo + rng.normal(0.0, 0.004, fo.shape))

    # what the log says: platform at +-90 at rest (end-stop switches), empty while moving
    plat_log = []
    for i in range(2):
        moving = np.interp(t_out, t_int, plat_moving[i].astype(float)) > 0
        side = np.interp(t_out, t_int, plat_side[i])
        plat_log.append(np.where(moving, np.nan, 90.0 * np.sign(side)))
    # (the half angles' cos and sin from math, as a row at a time would: numpy's may differ in
    # the last bit; the product elementwise, the same operations as quat_mul on one row)
    half_yaw = (np.interp(t_out, t_int, yaw) / 2).tolist()
    half_pitch = (np.interp(t_out, t_int, pitch) / 2).tolist()
    zero = np.zeros(n_out)
    qz = (np.array([math.cos(h) for h in half_yaw]), zero, zero, np.array([math.sin(h) for h in half_yaw]))
    qy = (np.array([math.cos(h) for h in half_pitch]), zero, np.array([math.sin(h) for h in half_pitch]), zero)
    q_out = quat_mul(qz, qy).T
    temp_out = np.interp(t_out, t_int, temp)

    if args.single:
        write_single(args, t_out, gyro[0], accel[0], q_out, temp_out)
        return 0
    with open(args.out, "w") as f:
        f.write("# format: driftless-log 1\n# complete: true\n")
        f.write(f"# sample_rate_hz: {fs:g}\n# latitude_deg: {args.latitude:g}\n")
        f.write("# hinge1_axis: 0 0 1\n# hinge2_axis: 1 0 0\n# source: independent generator (tests/diagnose)\n")
        f.write(f"# seed: {args.seed}\n")
        cols = "t,gyro1_x,gyro1_y,gyro1_z,gyro2_x,gyro2_y,gyro2_z,plat1_deg,plat2_deg,ref_qw,ref_qx,ref_qy,ref_qz"
        f.write(cols + (",temp1,temp2\n" if args.temperature else "\n"))
        head = rows_text([(t_out[:, None], "%.6f"), (gyro[0], "%.7f"), (gyro[1], "%.7f")]).split("\n")
        angles = [["" if math.isnan(v) else "%.6f" % v for v in plat_log[i].tolist()] for i in range(2)]
        tail = [(q_out, "%.10f")] + ([(temp_out[:, None], "%.3f")] * 2 if args.temperature else [])
        rows = zip(head, angles[0], angles[1], rows_text(tail).split("\n"))
        f.write("".join(f"{h},{a1},{a2},{r}\n" for h, a1, a2, r in rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
