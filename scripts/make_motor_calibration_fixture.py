#!/usr/bin/env python3
"""Writes datasets/fixtures/motor_calibration_example.csv: a synthetic BeagleBone-style calibration
(`channel,duty,speed`) from known lines, so config/calibrate_motors.ini has an input that needs no
robot. The true lines (duty = slope * speed + punch) are in the file's header comment; samples below
the punch stall (speed 0), speeds carry 0.05 rad/s noise, and 3 samples per wheel are slips (speed
40 % low). Deterministic (seeded)."""
import os
import random

TRUE = {  # channel: (forward slope, forward punch, backward slope, backward punch)
    1: (0.0620, 0.0700, 0.0640, -0.0720),  # left
    2: (0.0700, 0.0650, 0.0690, -0.0660),  # right
}

def main():
    rng = random.Random(550)
    out = os.path.join(os.path.dirname(__file__), "..", "datasets", "fixtures", "motor_calibration_example.csv")
    lines = ["# Synthetic motor calibration (scripts/make_motor_calibration_fixture.py), not a real robot.",
             "# True lines, duty = slope * speed + punch:"]
    for ch, (fs, fp, bs, bp) in TRUE.items():
        lines.append(f"#   channel {ch}: forward slope {fs} punch {fp}; backward slope {bs} punch {bp}")
    lines.append("channel,duty,speed")
    for ch, (fs, fp, bs, bp) in TRUE.items():
        duties = [round(-0.6 + 0.01 * i, 3) for i in range(121)]
        slips = set(rng.sample(range(len(duties)), 3))
        for i, d in enumerate(duties):
            if d > fp:
                w = (d - fp) / fs
            elif d < bp:
                w = (d - bp) / bs
            else:
                w = 0.0
            if w != 0.0:
                w += rng.gauss(0.0, 0.05)
                if i in slips:
                    w *= 0.6
            lines.append(f"{ch},{d:.3f},{w:.4f}")
    with open(out, "w") as f:
        f.write("\n".join(lines) + "\n")

if __name__ == "__main__":
    main()
