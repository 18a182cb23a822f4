#!/usr/bin/env python3
"""tools/bench/cost_model.py — per-rank cost of the steps that run on P ranks
(datasets-spec/parallel.md): bytes read, flops, messages and bytes sent, memory
held, for PCA's Gram and randomized routes (lib/stats/pca.c, pca_parallel.c,
pca_strip.c, pca_randomized.c), GPA (lib/procrustes/gpa.c, es_gpa_align_ranks)
and mesh ingest (lib/ingest/ingest_ranks.c, lib/store/store_ranks.c), as the
code runs them.

    python3 tools/bench/cost_model.py [--rows N] [--edges E] [--components K]
        [--oversample p] [--power q] [--gpa-iterations I] [--power-steps S]
        [--mesh-bytes B] [--ranks 1,2,4,...]

Defaults: the issue's cohort, 100,000 subjects x 175,000 edges (closed meshes of
V = (E + 6) / 3 vertices), top 20 (p = 10, q = 4), P = 1 ... 256.

"messages" and "sent" are rank 0's, counted as the library counts them
(es_parallel_traffic, lib/parallel/parallel.c): an agreement (es_parallel_agree,
one all-reduce of an int) is 1 message of 4 bytes; the root of a broadcast
sends P - 1 messages of its bytes (Open MPI sends along a tree: the count is of
the copies the other ranks receive); a reduction or gather to rank 0
costs rank 0 nothing (every other rank sends it 1 message); an all-gather is
P - 1 messages of the rank's share; an all-to-all one message to each rank it
sends a non-empty part. Collective HDF5 writes (ingest) are HDF5's own MPI-IO
traffic, not counted: the model gives the bytes a rank writes instead.
tests/parallel/check_cost_model.py checks read, messages and sent against
what the routes count as they run, at P = 1, 2, 4.

Every function returns a dict: "read" (bytes, the rank that reads most),
"reads" (bytes per rank, rank 0 first), "flops" (a rank's share), "root_flops"
(rank 0's extra), "messages", "sent", "memory"; the model assumes N >= P and
E >= P (every rank has rows and edges).
"""
import argparse
import math

# the library's constants (the files named)
ROUND_BYTES = 64 << 20    # pca_parallel.c: rows a round of the all-to-all exchange
TILE_BYTES = 256 << 20    # pca.c: one process's Gram tiles
BLOCK_BYTES = 128 << 20   # stats.c: rows a read (es__source_block)
INGEST_BYTES = 64 << 20   # ingest_read.c: positions and lengths a block (block_rows)
GRAM_LIMIT = 2e8          # gpa.c: Ten Berge from the explicit n x n Gram matrix up to this
AGREE = 4                 # parallel.c: an agreement's int
HASH = 25                 # es_content_hash: "fnv1a64:" + 16 hex digits + NUL
OBJ_BYTES_PER_VERTEX = 60  # OBJ files of ../shared (F ~ 2 V): 57 to 64 bytes a vertex


def share(n, P, q):
    """Items of n that rank q of P takes (es__par_split: the first n % P take one more)."""
    return n // P + (q < n % P)


def gram(N, E, K, P, block=None):
    """PCA, Gram route: K the components found. One process (pca.c) reads row 0,
    then square tiles of B rows (TILE_BYTES) against every later block, then all
    rows again for the components. On P ranks (pca_parallel.c) each reads its
    rows once, in rounds of B rows (ROUND_BYTES), and exchanges them all-to-all
    into strips of edges; the N x N Gram matrices are reduced to rank 0, which
    decomposes and broadcasts them; components and mean are gathered."""
    n0, e0 = share(N, P, 0), share(E, P, 0)
    if P == 1:
        B = min(max(1, block or TILE_BYTES // (8 * E)), N)
        held = 2 * E * B                                  # a tile and the block against it
        rows = 1 + sum(N - i0 for i0 in range(0, N, B)) + (N if K > 0 else 0)
        reads = [8 * E * rows]
        messages = sent = 0
    else:
        B = max(1, block or ROUND_BYTES // (8 * E))
        rounds = math.ceil(n0 / B)
        held = 2 * E * min(B, n0) + e0 * N                # a round's rows, sent; its strip
        reads = [8 * E * share(N, P, q) for q in range(P)]
        agrees = 9 + rounds   # allocations, each round's read, Gram, decomposition, ...
        messages = (agrees
                    + rounds * (min(P, E) - 1)            # rows to the other ranks' strips
                    + (P - 1) * (2 + 3 * (K > 0) + 2))    # r and trace; w, V, norms; 2 gathers
        sent = (AGREE * agrees
                + 8 * n0 * (E - e0)                       # its rows' other edges
                + 8 * (P - 1) * (3                        # r (2 int64) and the trace
                                 + K * (2 + N)            # eigenvalues, eigenvectors, norms
                                 + e0 * (K + 1)))         # its components' and mean's edges
    return {
        "read": max(reads), "reads": reads,
        "flops": N * N * e0 + 2 * e0 * N * K,
        "root_flops": 4 / 3 * N ** 3 + 4 * N * N * K,             # dsyevr, rank 0
        "messages": messages, "sent": sent,
        "memory": 8 * (held + N * N + E * K + 2 * N * K),         # + G, components, V, scores
    }


def randomized(N, E, K, P, p=10, q=4, block=None):
    """PCA, randomized route (pca_randomized.c): every rank reads row 0, then its
    rows q + 2 times in rounds of B rows (BLOCK_BYTES); per pass the E x l
    products are summed (reduced to rank 0 and broadcast) and rank 0's QR
    broadcast; A^T Q's rows are gathered; rank 0's SVD results broadcast."""
    l = min(K + min(p, N), N, E)
    B = min(max(1, block or BLOCK_BYTES // (8 * E)), N)
    n0 = share(N, P, 0)
    rounds = math.ceil(n0 / B)
    reads = [8 * E * (1 + (q + 2) * share(N, P, r)) for r in range(P)]
    if P == 1:
        messages = sent = 0
    else:
        agrees = (q + 2) * rounds + 2 * q + 6   # each round's read, each QR, progress, ...
        messages = agrees + (P - 1) * (2 * q + 7)
        sent = (AGREE * agrees
                + 8 * (P - 1) * ((E + 1)                   # column sums and sum of squares
                                 + 2 * (q + 1) * E * l     # Y summed, Q, each pass
                                 + n0 * l                  # its rows of A^T Q
                                 + K * (E + 1 + N)))       # components, eigenvalues, scores
    return {
        "read": max(reads), "reads": reads,
        "flops": 2 * E * n0 * l * (2 * q + 2),
        "root_flops": 4 * E * l * l * (q + 1) + 4 * N * l * l,  # QR per pass, SVD of N x l
        "messages": messages, "sent": sent,
        "memory": 8 * (3 * E * l + 2 * N * l + E * min(n0, B)),
    }


def gpa(N, k, d, P, iterations, power_steps=0, scale=True):
    """GPA on the ranks (gpa.c, es_gpa_align_ranks, every output asked for as
    `edgespace gpa` asks): I = iterations sweeps, each a chain of P broadcasts
    of the running sum (kd + 1 doubles; rank 0 is root once) and, for full GPA,
    a Ten Berge step: exact (N^2 kd <= GRAM_LIMIT) rank 0 gathers the shares,
    decomposes, broadcasts phi and the sum is rebuilt by a chain; otherwise
    power_steps S steps in all, each but the first of a scaling step a chain of
    kd, each an all-gather of the rank's dots. "reads": the positions the store
    command reads (3 k doubles a row of its share; es_gpa_align_ranks itself
    is handed the share, so the check does not measure this term)."""
    kd, I = k * d, iterations
    n0 = share(N, P, 0)
    exact = scale and N * N * kd <= GRAM_LIMIT
    S = power_steps if scale and not exact else 0
    power_chains = S - I if S else 0
    reads = [8 * 3 * k * share(N, P, r) for r in range(P)]
    if P == 1:
        messages = sent = 0
    else:
        agrees = (1 + 1 + 3                 # memory, centring, 3 gathers (norms, sizes, centroids)
                  + I * (1 + 3 * exact)     # sweep; exact: memory, decomposition, flush
                  + power_chains + S        # power: chains, gathers of the dots
                  + 4)                      # flush, fit, 2 gathers (rho, rotations)
        chains = 1 + I + I * exact + 1 + power_chains + 1   # centre, sweeps, flushes, power, fit
        messages = agrees + (P - 1) * (chains + 5 + S + I * exact)   # gathers, phi
        sent = (AGREE * agrees
                + 8 * (P - 1) * ((1 + I) * (kd + 1)             # centring and sweep chains
                                 + (I * exact + 1 + power_chains) * kd  # sums rebuilt, power
                                 + 2                            # GSS and rho chain
                                 + n0 * (3 + d + d * d)         # norms, sizes, rho, centroids,
                                 + S * n0                       #   rotations; the dots
                                 + I * exact * N))              # phi
    return {
        "read": max(reads), "reads": reads,
        # a sweep's cross products and rotations, 4 d kd a configuration; the
        # ranks take their shares in turn, so a sweep takes P times this
        "flops": I * 4 * d * kd * n0 + S * 4 * kd * n0,
        "root_flops": I * (N * N * kd + 4 / 3 * N ** 3) if exact else 0,
        "messages": messages, "sent": sent,
        "memory": 8 * (n0 * kd + kd + 1 + max(kd, N * N if exact else 0) + 5 * N + d * d * N
                       + (N * kd if exact and P > 1 else 0)),
    }


def ingest(N, V, E, F, P, sizes=None, known=None, created=True, block=None, threads=16,
           path_bytes=100, warned=0):
    """Mesh ingest (ingest_ranks.c): every rank reads its share of the files in
    rounds of B inputs (INGEST_BYTES of positions and lengths, at least one a
    thread), and besides, on P ranks, the first file (a new store: every rank
    takes the topology from it; rank 0 reads it once) and the inputs of its share
    whose id the store has (read for their hash before the rounds, then again).
    sizes: bytes of each input (default OBJ_BYTES_PER_VERTEX V each); known:
    per input, 1 if the store has its id and content (skipped). path_bytes: the
    working copy's path, sent to every rank (its length depends on the pid and
    the clock). warned: ranks other than 0 with warnings to forward."""
    sizes = sizes or [OBJ_BYTES_PER_VERTEX * V] * N
    known = known or [0] * N
    kept = N - sum(known)
    n0 = share(N, P, 0)
    reads = []
    for q in range(P):
        lo = q * (N // P) + min(q, N % P)
        mine = range(lo, lo + share(N, P, q))
        again = sum(sizes[i] for i in mine if known[i]) if P > 1 else 0
        first = sizes[0] if created and P > 1 and q > 0 else 0
        reads.append(sum(sizes[i] for i in mine) + again + first)
    per = 8 * (3 * V + E)
    B = block or max(INGEST_BYTES // per, min(threads, n0))
    rounds = math.ceil(n0 / B)
    if P == 1:
        messages = sent = 0
    else:
        agrees = (4                                  # begin, skips, rows, the end
                  + (6 + 4 * rounds) * (kept > 0)    # MPI-IO open; each round: read, 3 writes
                  + warned)
        messages = agrees + (P - 1) * (2 + 2 * (n0 > 0) + 1 + 3 * (kept > 0))
        sent = (AGREE * agrees
                + (P - 1) * (24                       # created, rows before, bytes read
                             + (1 + HASH) * n0        # its skip flags and hashes
                             + (16 + path_bytes) * (kept > 0)))   # the copy's path, rounds
    return {
        "read": max(reads), "reads": reads,
        "flops": share(N, P, 0) * 13 * E,            # lengths (9 E) and normalization (4 E)
        "root_flops": 0,
        "messages": messages, "sent": sent,
        # a block of positions and lengths, hashes and skip flags of all inputs
        "memory": min(B, n0) * per + (HASH + 1) * N,
        # HDF5's collective writes (not counted as messages): this rank's kept
        # rows; rank 0 besides writes every new row's space once (allocation)
        "written": sum(1 for i in range(n0) if not known[i]) * (per + 8),
        "root_written": kept * (per + 8),
    }


def fmt(v, unit=""):
    for s, d in (("P", 1e15), ("T", 1e12), ("G", 1e9), ("M", 1e6), ("k", 1e3)):
        if abs(v) >= d:
            return f"{v / d:.3g} {s}{unit}"
    return f"{v:.3g} {unit}".strip()


def table(name, f, ranks, extra=None):
    print(f"\n{name}, per rank:")
    head = f"{'P':>5} {'read':>10} {'flops':>10} {'rank-0 extra':>13} {'messages':>9} " \
           f"{'sent (0)':>10} {'memory':>10}"
    print(head + (f" {extra[0]:>10}" if extra else ""))
    for P in ranks:
        c = f(P)
        line = (f"{P:>5} {fmt(c['read'], 'B'):>10} {fmt(c['flops']):>10} "
                f"{fmt(c['root_flops']):>13} {c['messages']:>9} {fmt(c['sent'], 'B'):>10} "
                f"{fmt(c['memory'], 'B'):>10}")
        print(line + (f" {fmt(c[extra[1]], 'B'):>10}" if extra else ""))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--rows", type=int, default=100_000)
    ap.add_argument("--edges", type=int, default=175_000)
    ap.add_argument("--components", type=int, default=20)
    ap.add_argument("--oversample", type=int, default=10)
    ap.add_argument("--power", type=int, default=4)
    # GPA's sweeps and power steps depend on the data: the defaults are what
    # the check's power-route run took (203 configurations of 1,700 vertices)
    ap.add_argument("--gpa-iterations", type=int, default=11, help="GPA sweeps")
    ap.add_argument("--power-steps", type=int, default=20,
                    help="Ten Berge power steps, all sweeps together")
    ap.add_argument("--mesh-bytes", type=int, default=0,
                    help=f"bytes of a mesh file (default {OBJ_BYTES_PER_VERTEX} V)")
    ap.add_argument("--ranks", default="1,2,4,8,16,32,64,128,256")
    a = ap.parse_args()
    N, E, K = a.rows, a.edges, a.components
    V, F = (E + 6) // 3, 2 * E // 3
    ranks = [int(x) for x in a.ranks.split(",")]
    I, S = a.gpa_iterations, a.power_steps
    mesh = a.mesh_bytes or OBJ_BYTES_PER_VERTEX * V
    print(f"N = {N}, E = {E}, K = {K}: {fmt(8 * N * E, 'B')} of lengths; meshes of V = {V}, "
          f"F = {F} ({fmt(mesh, 'B')} a file)")
    table("Gram (exact)", lambda P: gram(N, E, K, P), ranks)
    table("randomized", lambda P: randomized(N, E, K, P, a.oversample, a.power), ranks)
    table(f"GPA (k = {V}, d = 3; {I} sweeps, {S} power steps)",
          lambda P: gpa(N, V, 3, P, I, S), ranks)
    table("ingest", lambda P: ingest(N, V, E, F, P, sizes=[mesh] * N), ranks,
          ("written", "written"))


if __name__ == "__main__":
    main()
