#!/usr/bin/env python3
"""MCAP read throughput: our `mcap` source against Foxglove's Python reader and rosbags, same bag.

Each reader reads every message and decodes it into its own objects: ours into the pipeline's
events (mbot_ros2_benchmark, Google Benchmark, the median of its repetitions), Foxglove's `mcap`
with `mcap-ros2-support` into ROS 2 message objects, rosbags' AnyReader + deserialize into its
dataclasses. Median of `runs` runs each, all in this one run of the script.

    bench_mcap.py <mbot_ros2_benchmark> <bag folder> [runs]
"""
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
from rosbags.highlevel import AnyReader

benchmark, bag = sys.argv[1], Path(sys.argv[2])
runs = int(sys.argv[3]) if len(sys.argv) > 3 else 3
mcap_file = next(bag.glob("*.mcap"))


def ours():
    with tempfile.TemporaryDirectory() as out:
        subprocess.run([benchmark, f"--benchmark_repetitions={runs}", "--benchmark_report_aggregates_only=true",
                        f"--benchmark_out={out}/b.json", "--benchmark_out_format=json"],
                       env={**os.environ, "MBOT_MCAP_BAG": str(bag)}, check=True, capture_output=True)
        report = json.loads(Path(out, "b.json").read_text())
    median = next(b for b in report["benchmarks"] if b.get("aggregate_name") == "median")
    rate = median["items_per_second"]
    return [(round(rate * median["real_time"] / 1000), median["real_time"] / 1000)]


def foxglove():
    t = time.perf_counter()
    n = 0
    with open(mcap_file, "rb") as f:
        for _ in make_reader(f, decoder_factories=[DecoderFactory()]).iter_decoded_messages(log_time_order=False):
            n += 1
    return n, time.perf_counter() - t


def rosbags():
    t = time.perf_counter()
    n = 0
    with AnyReader([bag]) as reader:
        for connection, _ts, raw in reader.messages():
            reader.deserialize(raw, connection.msgtype)
            n += 1
    return n, time.perf_counter() - t


results = {}
for name, fn in (("mbot_nav mcap source", ours), ("Foxglove mcap + mcap-ros2-support", foxglove),
                 ("rosbags AnyReader", rosbags)):
    samples = fn() if fn is ours else [fn() for _ in range(runs)]
    n = samples[0][0]
    wall = statistics.median(s[1] for s in samples)
    results[name] = (n, wall)
    print(f"{name:36s} {n:8d} messages  median {wall:8.3f} s  {n / wall:12,.0f} messages/s")
ours_rate = results["mbot_nav mcap source"][0] / results["mbot_nav mcap source"][1]
best = max(n / w for k, (n, w) in results.items() if k != "mbot_nav mcap source")
print(f"ours / the faster Python reader: {ours_rate / best:.1f}x")
