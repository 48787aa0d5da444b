#!/usr/bin/env python3
"""An EuRoC-layout folder written apart from the twin (no MuJoCo, no project code): one IMU at the
centre of a body turning about all three axes in front of motion capture.

  euroc_layout.py OUT SEED SCALE_X_PCT DURATION_S

writes OUT/imu0/data.csv (200 Hz: ns stamp, gyro in rad/s, accelerometer in m/s^2, the EuRoC
header) and OUT/state_groundtruth_estimate0/data.csv (200 Hz, offset by half a step, starting
0.5 s after the IMU and ending 0.5 s before it: position, q_RS wxyz, velocity, biases).
Body rate (rad/s, body axes): three sines of 0.17-0.31 Hz, up to 46 deg/s; the attitude is
their integral (4th-order Runge-Kutta on the quaternion at 0.5 ms). The gyro reads the body rate
with its x axis SCALE_X_PCT % high, turn-on biases (0.3, 0, -0.2 deg/s) and MPU6050 white noise
(0.005 deg/s/sqrt(Hz)); the accelerometer reads gravity in body axes with 400 ug/sqrt(Hz).
No low-pass filter, no Earth rate, no temperature.
"""
import math
import os
import random
import sys

out, seed, scale_x_pct, duration_s = sys.argv[1], int(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4])
rng = random.Random(seed)
RATE_HZ = 200.0
T0_NS = 1403636579758555392
G = 9.81  # m/s^2
SINES = [(0.60, 0.23, 0.0), (0.50, 0.31, 1.0), (0.80, 0.17, 2.0)]  # rad/s, Hz, rad


def rate(t):
    return [a * math.sin(2 * math.pi * f * t + ph) for a, f, ph in SINES]


def qmul(a, b):
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return (aw * bw - ax * bx - ay * by - az * bz, aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx, aw * bz + ax * by - ay * bx + az * bw)


def qdot(q, w):  # dq/dt = q (0, w) / 2, w in body axes
    return tuple(0.5 * c for c in qmul(q, (0.0, w[0], w[1], w[2])))


def rk4(q, t, h):
    k1 = qdot(q, rate(t))
    k2 = qdot(tuple(q[i] + 0.5 * h * k1[i] for i in range(4)), rate(t + 0.5 * h))
    k3 = qdot(tuple(q[i] + 0.5 * h * k2[i] for i in range(4)), rate(t + 0.5 * h))
    k4 = qdot(tuple(q[i] + h * k3[i] for i in range(4)), rate(t + h))
    q = tuple(q[i] + h / 6 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]) for i in range(4))
    n = math.sqrt(sum(c * c for c in q))
    return tuple(c / n for c in q)


def body_from_ref(q, v):  # R(q)^T v
    w, x, y, z = q
    conj = qmul(qmul((w, -x, -y, -z), (0.0, v[0], v[1], v[2])), q)
    return conj[1:]


# attitude at every half step (2.5 ms): IMU samples on even, ground truth on odd indices
SUB = 5  # RK4 substeps of 0.5 ms per half step
h = 0.5 / RATE_HZ / SUB
n_half = int(round(duration_s * RATE_HZ * 2))
att = [(1.0, 0.0, 0.0, 0.0)]
q = att[0]
for k in range(n_half):
    for j in range(SUB):
        q = rk4(q, (k * SUB + j) * h, h)
    att.append(q)

os.makedirs(os.path.join(out, "imu0"), exist_ok=True)
os.makedirs(os.path.join(out, "state_groundtruth_estimate0"), exist_ok=True)
gyro_sigma = math.radians(0.005) * math.sqrt(RATE_HZ / 2)  # rad/s per sample
accel_sigma = 400e-6 * G * math.sqrt(RATE_HZ / 2)  # m/s^2 per sample
bias = [math.radians(b) for b in (0.3, 0.0, -0.2)]
scale = [1.0 + scale_x_pct / 100.0, 1.0, 1.0]
with open(os.path.join(out, "imu0", "data.csv"), "w") as f:
    f.write("#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],"
            "a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\n")
    for k in range(0, n_half + 1, 2):
        t = k * 0.5 / RATE_HZ
        w = rate(t)
        g = [scale[i] * w[i] + bias[i] + rng.gauss(0, gyro_sigma) for i in range(3)]
        a = [c + rng.gauss(0, accel_sigma) for c in body_from_ref(att[k], (0.0, 0.0, G))]
        f.write("%d,%.9f,%.9f,%.9f,%.6f,%.6f,%.6f\n" % ((T0_NS + k * 2500000,) + tuple(g) + tuple(a)))
with open(os.path.join(out, "state_groundtruth_estimate0", "data.csv"), "w") as f:
    f.write("#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], q_RS_z [], "
            "v_RS_R_x [m s^-1], v_RS_R_y [m s^-1], v_RS_R_z [m s^-1], b_w_RS_S_x [rad s^-1], "
            "b_w_RS_S_y [rad s^-1], b_w_RS_S_z [rad s^-1], b_a_RS_S_x [m s^-2], b_a_RS_S_y [m s^-2], "
            "b_a_RS_S_z [m s^-2]\n")
    margin = int(round(0.5 * RATE_HZ * 2))
    for k in range(1 + margin, n_half - margin, 2):
        q = att[k]
        f.write("%d,0.5,-1.2,0.8,%.12f,%.12f,%.12f,%.12f,0,0,0,0,0,0,0,0,0\n" % ((T0_NS + k * 2500000,) + q))
