#!/usr/bin/env python3
"""How a run's estimated path compares with the truth in shape: the 2D similarity (scale, rotation,
translation) that best maps the estimate onto the truth in least squares, pose by pose.

  scripts/path_scale.py <run dir> [<run dir> ...]

Reads <run dir>/slam.tum and <run dir>/ground_truth.tum (the same scan times, as mbot_nav writes
them) and prints, per run: the estimate's scale (below 1: the estimated path and the map it drew
are smaller than the world), the rotation, and the RMSE and largest error left after the fit; then
the heading error the estimate gained while the robot turned left, turned right and drove straight
(a share of the turn: positive = turned farther than the robot did), and the RMS heading error.
Pure Python: no numpy needed.
"""
import math
import sys


def read_tum(path):
    poses = []
    with open(path) as f:
        for number, line in enumerate(f, 1):
            if line.startswith("#") or not line.strip():
                continue
            fields = line.split()
            if len(fields) < 8:
                sys.exit(f"{path}:{number}: expected 8 fields (t x y z qx qy qz qw), got {len(fields)}")
            qz, qw = float(fields[6]), float(fields[7])
            poses.append((float(fields[0]), complex(float(fields[1]), float(fields[2])), 2 * math.atan2(qz, qw)))
    return poses


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    for run in sys.argv[1:]:
        estimate = read_tum(f"{run}/slam.tum")
        truth = read_tum(f"{run}/ground_truth.tum")
        if len(estimate) != len(truth) or any(abs(a[0] - b[0]) > 1e-6 for a, b in zip(estimate, truth)):
            sys.exit(f"{run}: slam.tum and ground_truth.tum are not at the same times")
        n = len(estimate)
        if n < 3:
            sys.exit(f"{run}: fewer than 3 poses")
        a = [p for _, p, _ in estimate]
        b = [p for _, p, _ in truth]
        ma, mb = sum(a) / n, sum(b) / n
        a = [p - ma for p in a]
        b = [p - mb for p in b]
        # truth ≈ k · estimate (k complex: scale and rotation), about the centroids.
        norm = sum(abs(p) ** 2 for p in a)
        if norm == 0:
            sys.exit(f"{run}: the estimated path does not move")
        k = sum(p.conjugate() * q for p, q in zip(a, b)) / norm
        errors = [abs(k * p - q) for p, q in zip(a, b)]
        rmse = math.sqrt(sum(e * e for e in errors) / n)
        print(f"{run}: estimate scale {1 / abs(k):.4f}, rotation {math.degrees(-math.atan2(k.imag, k.real)):+.2f} deg, "
              f"after the fit RMSE {rmse:.4f} m, largest {max(errors):.4f} m ({n} poses)")
        # Heading error gained per scan, by what the robot did over it (turning: over 0.02 rad a scan).
        wrap = lambda x: (x + math.pi) % (2 * math.pi) - math.pi
        gained = {"left": [0.0, 0.0], "right": [0.0, 0.0], "straight": [0.0, 0.0]}
        for i in range(1, n):
            turned = wrap(truth[i][2] - truth[i - 1][2])
            error_change = wrap(estimate[i][2] - truth[i][2]) - wrap(estimate[i - 1][2] - truth[i - 1][2])
            kind = "left" if turned > 0.02 else "right" if turned < -0.02 else "straight"
            gained[kind][0] += error_change
            gained[kind][1] += abs(turned)
        heading_rms = math.sqrt(sum(wrap(e[2] - t[2]) ** 2 for e, t in zip(estimate, truth)) / n)
        parts = []
        for kind, sign in (("left", 1), ("right", -1)):
            g, t = gained[kind]
            parts.append(f"turning {kind} {math.degrees(g):+.2f} deg over {math.degrees(t):.0f} deg"
                         + (f" ({100 * sign * g / t:+.2f} % of the turn)" if t > 0 else ""))
        parts.append(f"straight {math.degrees(gained['straight'][0]):+.2f} deg")
        print(f"  heading error gained: {', '.join(parts)}; RMS heading error {math.degrees(heading_rms):.3f} deg")


if __name__ == "__main__":
    main()
