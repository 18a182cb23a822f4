#!/usr/bin/env python3
"""tools/bench/cost_model.py — per-rank cost of PCA on P ranks (datasets-spec/parallel.md):
bytes read, flops, messages and bytes sent, memory held, for the Gram and the randomized
routes as lib/stats/pca_parallel.c, pca_strip.c and pca_randomized.c run them.

    python3 tools/bench/cost_model.py [--rows N] [--edges E] [--components K]
                                      [--oversample p] [--power q] [--ranks 1,2,4,...]

Defaults: the issue's cohort, 100,000 subjects x 175,000 edges, top 20 (p = 10, q = 4),
P = 1 ... 256. Rows are read in rounds of ROUND_BYTES (64 MB) per rank.
"""
import argparse
import math

ROUND_BYTES = 64 << 20


def gram(N, E, K, P):
    n, e = math.ceil(N / P), math.ceil(E / P)
    rounds = max(1, math.ceil(n / max(1, ROUND_BYTES // (8 * E))))
    return {
        "read": 8 * n * E,
        "flops": N * N * e + 2 * e * N * K,
        "root_flops": 4 / 3 * N ** 3 + 4 * N * N * K,            # dsyevr, rank 0
        "messages": rounds * (P - 1) + 1 + 2 * (P - 1) + 12,       # all-to-all, reduce, gathers, agree
        "sent": 8 * (n * E * (P - 1) / P + N * N * (P > 1) + e * (K + 1) * (P - 1)),
        "memory": 8 * (n * E + e * N + N * N + E * K + N * K),
    }


def randomized(N, E, K, P, p=10, q=4):
    l = K + p
    n = math.ceil(N / P)
    passes = q + 2
    return {
        "read": 8 * n * E * passes,
        "flops": 2 * E * n * l * (2 * q + 2),
        "root_flops": 4 * E * l * l * (q + 1) + 4 * N * l * l,  # QR per pass, SVD of N x l
        "messages": (q + 1) * 2 + (q + 1) * (P - 1) + (P - 1) + 12,
        # rank 0: per pass Q and the summed Y broadcast (P - 1 sends each, as counted
        # by es_ctx_parallel_traffic), then its rows of A^T Q to every rank
        "sent": 8 * (2 * (q + 1) * E * l * (P - 1) + n * l * (P - 1)),
        "memory": 8 * (3 * E * l + 2 * N * l + E * min(n, ROUND_BYTES // (8 * E) or 1)),
    }


def fmt(v, unit=""):
    for s, d in (("P", 1e15), ("T", 1e12), ("G", 1e9), ("M", 1e6), ("k", 1e3)):
        if abs(v) >= d:
            return f"{v / d:.3g} {s}{unit}"
    return f"{v:.3g} {unit}".strip()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--rows", type=int, default=100_000)
    ap.add_argument("--edges", type=int, default=175_000)
    ap.add_argument("--components", type=int, default=20)
    ap.add_argument("--oversample", type=int, default=10)
    ap.add_argument("--power", type=int, default=4)
    ap.add_argument("--ranks", default="1,2,4,8,16,32,64,128,256")
    a = ap.parse_args()
    N, E, K = a.rows, a.edges, a.components
    print(f"N = {N}, E = {E}, K = {K}: {fmt(8 * N * E, 'B')} of lengths")
    for name, f in (("Gram (exact)", lambda P: gram(N, E, K, P)),
                    ("randomized", lambda P: randomized(N, E, K, P, a.oversample, a.power))):
        print(f"\n{name}, per rank:")
        print(f"{'P':>5} {'read':>10} {'flops':>10} {'rank-0 extra':>13} {'messages':>9} "
              f"{'sent (0)':>10} {'memory':>10}")
        for P in (int(x) for x in a.ranks.split(",")):
            c = f(P)
            print(f"{P:>5} {fmt(c['read'], 'B'):>10} {fmt(c['flops']):>10} "
                  f"{fmt(c['root_flops']):>13} {c['messages']:>9} {fmt(c['sent'], 'B'):>10} "
                  f"{fmt(c['memory'], 'B'):>10}")


if __name__ == "__main__":
    main()
