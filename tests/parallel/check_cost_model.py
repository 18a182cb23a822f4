#!/usr/bin/env python3
"""tests/parallel/check_cost_model.py — tools/bench/cost_model.py against what
the routes count as they run (tests/parallel/parallel_counts.c), at P = 1, 2, 4.

For every route (PCA Gram and randomized, GPA exact, power and partial, ingest
into a new store and appended to it) and P, it compares with the model's
function for the same sizes:
  - the bytes each rank read (the row source's callback, or ingest's count of
    mesh-file bytes), rank by rank: exact;
  - rank 0's messages (es_parallel_traffic): exact;
  - rank 0's bytes sent: exact. One term of ingest's is the length of the
    store's working copy's path, which rank 0 broadcasts: its name holds the pid
    and the clock (.<name>.tmp-<pid>-<pointer><ns><n>), so parallel_counts finds
    it in the directory while the ingest runs and the model takes it from
    there; that it is within the name's bounds is checked too.
GPA's read term is not measured: es_gpa_align_ranks is handed each rank's share
(the store command reads it), so there it checks messages and bytes only.

Usage: check_cost_model.py PARALLEL_COUNTS [--mpirun MPIRUN] [--ranks 1,2,4].
Prints the counts it compared; exit 1 on any difference.
"""
import argparse
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "tools", "bench"))
import cost_model  # noqa: E402


def parse(path):
    routes = {}
    with open(path, encoding="utf-8") as f:
        for line in f:
            kv = dict(tok.split("=", 1) for tok in line.split())
            routes[kv["route"]] = kv
    return routes


def ints(s):
    return [int(x) for x in s.split(",")]


def model(route, c):
    """The model's costs for the sizes a count line gives."""
    P = int(c["P"])
    if route == "pca_gram":
        return cost_model.gram(int(c["N"]), int(c["E"]), int(c["K"]), P, int(c["block"]))
    if route == "pca_randomized":
        return cost_model.randomized(int(c["N"]), int(c["E"]), int(c["K"]), P,
                                     int(c["oversample"]), int(c["power"]), int(c["block"]))
    if route.startswith("gpa"):
        return cost_model.gpa(int(c["n"]), int(c["k"]), int(c["d"]), P, int(c["iterations"]),
                              int(c["power_steps"]), bool(int(c["scale"])))
    if route.startswith("ingest"):
        return cost_model.ingest(int(c["N"]), int(c["V"]), int(c["E"]), int(c["F"]), P,
                                 sizes=ints(c["sizes"]), known=ints(c["known"]),
                                 created=bool(int(c["created"])), block=int(c["block"]),
                                 path_bytes=int(c["work_path"]))
    raise KeyError(route)


def path_bounds(store):
    """Bytes of the working copy's path with its NUL (store_publish.c:
    "<dir>/.<base>.tmp-<pid>-<pointer %lx><ns %lx><counter %u>")."""
    fixed = len(store.encode()) + len(".") + len(".tmp-") + len("-") + 1
    return fixed + 1 + 1 + 1 + 1, fixed + 7 + 16 + 8 + 10   # pid <= 4194304 (7 digits)


def check(P, counts, report):
    bad = []
    routes = counts[0]
    for route, c0 in routes.items():
        m = model(route, c0)
        what = f"P = {P}, {route}"
        if not route.startswith("gpa"):
            got = [int(counts[q][route]["read"]) for q in range(P)]
            if got != m["reads"]:
                bad.append(f"{what}: read per rank {got}, model {m['reads']}")
        msgs, sent = int(c0["messages"]), int(c0["sent"])
        if msgs != m["messages"]:
            bad.append(f"{what}: rank 0 sent {msgs} messages, model {m['messages']}")
        if sent != m["sent"]:
            bad.append(f"{what}: rank 0 sent {sent} bytes, model {m['sent']}")
        note = ""
        if route.startswith("ingest"):
            lo, hi = path_bounds(c0["store"])
            if not lo <= int(c0["work_path"]) <= hi:
                bad.append(f"{what}: the working copy's path has {c0['work_path']} bytes, not "
                           f"{lo} to {hi}: parallel_counts did not find it")
            note = f" (working copy's path {c0['work_path']} bytes)"
        extra = (f"I = {c0['iterations']}, S = {c0['power_steps']}" if route.startswith("gpa")
                 else f"read per rank {[int(counts[q][route]['read']) for q in range(P)]}")
        report.append(f"{P:>2} {route:<15} messages {msgs:>5} sent {sent:>9}{note}; {extra}")
    return bad


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("counts", help="the parallel_counts program")
    ap.add_argument("--mpirun", help="run under this mpirun (else alone: P = 1 only)")
    ap.add_argument("--ranks", default="1,2,4")
    a = ap.parse_args()
    bad, report = [], []
    for P in (int(x) for x in a.ranks.split(",")):
        if P > 1 and not a.mpirun:
            sys.exit("P > 1 needs --mpirun")
        with tempfile.TemporaryDirectory(prefix=f"cost-model-np{P}-") as d:
            cmd = ([a.mpirun, "-n", str(P), "--oversubscribe", "--allow-run-as-root"]
                   if a.mpirun else []) + [a.counts, d]
            r = subprocess.run(cmd, capture_output=True, text=True, timeout=240)
            if r.returncode != 0:
                bad.append(f"P = {P}: {' '.join(cmd)} exited {r.returncode}:\n{r.stdout}{r.stderr}")
                continue
            counts = [parse(os.path.join(d, f"rank-{q}.txt")) for q in range(P)]
            if any(int(c["P"]) != P for c in counts[0].values()):
                bad.append(f"P = {P}: the counts say another number of ranks")
                continue
            bad += check(P, counts, report)
    print("\n".join(report))
    for b in bad:
        print("MISMATCH:", b, file=sys.stderr)
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
