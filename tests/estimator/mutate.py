#!/usr/bin/python3
"""mutate.py IN OUT MODE: a user's mistakes on a driftless log.
MODE rad_gyro: gyro columns in rad/s; rad_plat: plat*_deg in radians; neg_plat: platform angle sign
reversed (left-hand rule); drop_hinges: hinge lines removed from the header; swap_sensors: gyro1<->gyro2 columns."""
import sys, math
fin, fout, mode = sys.argv[1:4]
hdr = None
with open(fin) as f, open(fout, "w") as o:
    for line in f:
        if line.startswith("#"):
            if mode == "drop_hinges" and line.startswith("# hinge"): continue
            o.write(line); continue
        if hdr is None:
            hdr = line.strip().split(","); idx = {n: i for i, n in enumerate(hdr)}; o.write(line); continue
        v = line.rstrip("\n").split(",")
        if mode == "rad_gyro":
            for n in hdr:
                if n.startswith("gyro"): v[idx[n]] = f"{math.radians(float(v[idx[n]])):.9f}"
        elif mode == "rad_plat":
            for n in ("plat1_deg", "plat2_deg"):
                if v[idx[n]]: v[idx[n]] = f"{math.radians(float(v[idx[n]])):.6f}"
        elif mode == "neg_plat":
            for n in ("plat1_deg", "plat2_deg"):
                if v[idx[n]]: v[idx[n]] = f"{-float(v[idx[n]]):.6f}"
        elif mode == "swap_sensors":
            for c in "xyz":
                a, b = idx[f"gyro1_{c}"], idx[f"gyro2_{c}"]; v[a], v[b] = v[b], v[a]
        o.write(",".join(v) + "\n")
