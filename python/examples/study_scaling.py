"""Throughput of voussoir.study (issue 31, item 4): a 24-case study of about 1 s per case on a
LocalCluster of 2 single-threaded workers, on 1 single-threaded worker, and as a serial loop in
this process with rayon on every core; and the per-case overhead.

    python python/examples/study_scaling.py [--cases 24] [--steps 700]

Each case steps a 300-block running-bond wall (``scenes.benchmark_wall``) settling under its
weight for ``steps`` steps, its parameter the number of steps, and returns its kinetic energy.
"""

import argparse
import os
import time

import voussoir as vs


def wall_case(steps, copy):
    m = vs.scenes.benchmark_wall(300)
    m.run_steps(steps)
    return {"kinetic_j": m.energies()["kinetic"]}


def empty_case(steps, copy):
    return {"kinetic_j": 0.0}


def timed(label, fn):
    start = time.perf_counter()
    out = fn()
    wall = time.perf_counter() - start
    print(f"{label:45s} {wall:7.2f} s", flush=True)
    return wall, out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cases", type=int, default=24)
    ap.add_argument("--steps", type=int, default=700)
    a = ap.parse_args()
    from distributed import Client, LocalCluster

    cases = [{"steps": a.steps, "copy": k} for k in range(a.cases)]
    results = {}
    one, _ = timed("one case, this process, rayon on all cores", lambda: wall_case(a.steps, 0))
    serial, s = timed("serial loop, rayon on all cores", lambda: vs.study.run(wall_case, cases, client="serial", progress=False))
    for workers in (1, 2):
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None,
                               env={"RAYON_NUM_THREADS": "1"})
        client = Client(cluster)
        client.submit(empty_case, 0, -1).result()  # workers up
        wall, t = timed(f"LocalCluster, {workers} single-threaded worker(s)", lambda: vs.study.run(wall_case, cases, client=client, progress=False))
        over, _ = timed(f"  {a.cases} empty cases on it (overhead)", lambda: vs.study.run(empty_case, cases, client=client, progress=False))
        results[workers] = (wall, over, t)
        assert t["kinetic_j"].tolist() == s["kinetic_j"].tolist(), "not bit-identical"
        client.close()
        cluster.close()
    w1, w2 = results[1][0], results[2][0]
    print(f"\n2 workers / 1 worker throughput: {w1 / w2:.2f}x; 2 workers / serial with rayon: {serial / w2:.2f}x")
    print(f"per-case overhead on 2 workers: {1e3 * results[2][1] / a.cases:.1f} ms; one case alone: {one:.2f} s")
    print(f"cores: {os.cpu_count()}; the numbers of every run are the serial loop's, bit for bit")


if __name__ == "__main__":
    main()
