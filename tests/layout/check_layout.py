#!/usr/bin/env python3
"""tests/layout/check_layout.py — the layout's contract (lib/README.md), checked
from the sources on every test run:

  1. lib/<module>/ includes only modules at or below its own place in the data
     flow (core < parallel < h5 < sparse < mesh < meshio < store < ingest < stats < procrustes <
     embed < morph < study < figure, synth), whether through their library-private headers or
     their public headers; siblings (figure, synth) do not include each other;
     the numerical modules (stats, procrustes, embed, morph) take arrays and row
     callbacks and include neither the store nor its HDF5 adapter (h5);
  2. a package header (<module>/<module>_pkg.h) is included only by its own
     module (and carries the #error guard that enforces it at compile time);
  3. the include graph has no circles;
  4. no file in lib/ is over 800 lines, no command file (tools/cmd/) over 250;
  5. hdf5.h only under lib/h5, cholmod.h only under lib/sparse, cairo.h only
     under lib/figure, mpi.h only under lib/parallel (among lib/, tools/ and notebooks-c/);
  6. tools/ and notebooks-c/ include no private header of the library;
  7. every public function is es_<family>_..., its family one of those its
     module owns (FAMILIES: the module's name, the types it defines, a few
     words such as es_bbox_), no family owned by two modules, and it is
     declared in a public header of that module (es_core.h states the rule).
  8. lib/README.md's module table is true: one row per module folder, in the
     data flow's order; each row's "foreign library" cell names exactly the
     foreign libraries its files include (README_LIBS), and its "may call"
     cell every module its files include;

Usage: check_layout.py SOURCE_ROOT. Prints every violation; exit 1 if any.
"""
import os
import re
import sys

ORDER = ["core", "parallel", "h5", "sparse", "mesh", "meshio", "store", "ingest", "stats",
         "procrustes", "embed", "morph", "study", "figure", "synth"]
LEVEL = {m: i for i, m in enumerate(ORDER)}
LEVEL["synth"] = LEVEL["figure"]          # beside figure, above study
PUBLIC = {
    "es_core.h": "core", "es_parallel.h": "parallel", "es_mesh.h": "mesh",
    "es_geom.h": "mesh", "es_io.h": "meshio",
    "es_store.h": "store", "es_ingest.h": "ingest", "es_landmarks.h": "ingest",
    "es_stats.h": "stats", "es_point.h": "stats", "es_model.h": "stats",
    "es_procrustes.h": "procrustes",
    "es_compare.h": "procrustes", "es_embed.h": "embed", "es_interp.h": "embed",
    "es_morph.h": "morph",
    "es_study.h": "study", "es_plot.h": "figure", "es_render.h": "figure",
    "es_figure.h": "figure", "es_synth.h": "synth",
}
# The families of public function names (es_<family>_...) each module owns:
# the name says which module's header declares it.
FAMILIES = {
    "core": {"clock", "csv", "ctx", "free", "make", "rng", "strerror", "version"},
    "parallel": {"parallel"},
    "mesh": {"bbox", "corner", "dihedral", "edge", "faces", "lengths", "mesh"},
    "meshio": {"meshdata", "meshio"},
    "store": {"store", "topology"},
    "ingest": {"content", "export", "id", "ingest", "landmarks", "manifest", "statismo"},
    "stats": {"design", "diff", "effect", "fdr", "formula", "group", "groups", "mean", "model",
              "pca", "point", "quantile", "source"},
    "procrustes": {"compare", "gpa", "procrustes"},
    "embed": {"embed", "embedder", "interp"},
    "morph": {"conformal", "data", "lri", "morph", "multiscale", "shape"},
    "study": {"study"},
    "figure": {"colormap", "figure", "heatmap", "histogram", "lines", "palette", "plot",
               "render", "scatter", "scree"},
    "synth": {"synth"},
}
# lib/README.md's names of the foreign libraries -> the headers that mean
# the module uses them
README_LIBS = {
    "libcsv": re.compile(r"^csv\.h$"), "Open MPI": re.compile(r"^mpi\.h$"),
    "HDF5": re.compile(r"^(hdf5|H5[A-Za-z]*)\.h$"), "CHOLMOD": re.compile(r"^cholmod[a-z_]*\.h$"),
    "OpenMP": re.compile(r"^omp\.h$"), "LAPACKE": re.compile(r"^lapacke[a-z_]*\.h$"),
    "BLAS": re.compile(r"^cblas[a-z_]*\.h$"), "cairo": re.compile(r"^cairo[a-z-]*\.h$"),
}
# The libraries that only one module may include: header pattern -> module
# (rule 5, which also covers tools/ and notebooks-c/)
FOREIGN = {README_LIBS["HDF5"]: "h5", README_LIBS["CHOLMOD"]: "sparse",
           README_LIBS["cairo"]: "figure", README_LIBS["Open MPI"]: "parallel"}
PUBLIC_FN = re.compile(r"ES_API\s+[^;(]*?\b(es_[a-z0-9_]+)\s*\(", re.S)
INCLUDE = re.compile(r'^\s*#\s*include\s*([<"])([^>"]+)[>"]', re.M)
LIB_MAX, CMD_MAX = 800, 250


def includes(path):
    with open(path, encoding="utf-8", errors="replace") as f:
        return INCLUDE.findall(f.read())


def nlines(path):
    with open(path, encoding="utf-8", errors="replace") as f:
        return sum(1 for _ in f)


NUMERIC = {"stats", "procrustes", "embed", "morph"}


def may_include(own, target):
    """own module may include target module (a level at or below, not a sibling)."""
    if own == target:
        return True
    if own in NUMERIC and target in ("store", "h5"):
        return False
    return LEVEL[target] < LEVEL[own]


def main(root):
    errors = []
    lib = os.path.join(root, "lib")
    graph = {}   # file -> files it includes (inside the tree)

    def resolve(inc, src):
        for base in (os.path.dirname(src), lib, os.path.join(lib, "include")):
            p = os.path.normpath(os.path.join(base, inc))
            if os.path.isfile(p):
                return p
        return None

    # lib/<module>/ and the public headers
    for dirpath, _, files in os.walk(lib):
        rel = os.path.relpath(dirpath, lib)
        for name in sorted(files):
            if not name.endswith((".c", ".h")):
                continue
            path = os.path.join(dirpath, name)
            shown = os.path.relpath(path, root)
            n = nlines(path)
            if n > LIB_MAX:
                errors.append(f"{shown}: {n} lines (lib/ files stay at or under {LIB_MAX})")
            if rel.startswith("include"):
                own = PUBLIC.get(name)          # None for edgespace.h: may include all
            else:
                own = rel.split(os.sep)[0]
                if own not in LEVEL:
                    errors.append(f"{shown}: lib/{own}/ is not a module of the data flow")
                    continue
                if name.endswith("_pkg.h"):
                    guard = f"ES_MODULE_{own.upper()}"
                    with open(path) as f:
                        text = f.read()
                    if f"#ifndef {guard}" not in text or "#error" not in text:
                        errors.append(f"{shown}: package header without its #ifndef {guard} "
                                      f"#error guard")
            graph[path] = []
            for kind, inc in includes(path):
                base = os.path.basename(inc)
                for pat, mod in FOREIGN.items():
                    if kind == "<" and pat.match(base) and own != mod:
                        errors.append(f"{shown}: includes <{inc}>, which only lib/{mod}/ may")
                if kind != '"':
                    continue
                target_path = resolve(inc, path)
                if target_path:
                    graph[path].append(target_path)
                if own is None:
                    continue
                if inc.startswith("edgespace/") or (rel.startswith("include") and
                                                     inc.startswith("es_")):
                    tmod = PUBLIC.get(base)
                    if base in ("edgespace.h",):
                        errors.append(f"{shown}: includes the umbrella header {inc}")
                    elif tmod and not may_include(own, tmod):
                        errors.append(f"{shown}: ({own}) includes {inc} of {tmod}, above it")
                elif "/" in inc:
                    tmod = inc.split("/")[0]
                    if tmod not in LEVEL:
                        continue
                    if not may_include(own, tmod):
                        errors.append(f"{shown}: ({own}) includes {inc} of {tmod}, above it")
                    if base.endswith("_pkg.h") and tmod != own:
                        errors.append(f"{shown}: includes {inc}, private to lib/{tmod}/")

    # tools/ and notebooks-c/: public API only
    for top in ("tools", "notebooks-c"):
        for dirpath, _, files in os.walk(os.path.join(root, top)):
            for name in sorted(files):
                if not name.endswith((".c", ".h")):
                    continue
                path = os.path.join(dirpath, name)
                shown = os.path.relpath(path, root)
                if top == "tools" and os.path.basename(dirpath) == "cmd":
                    n = nlines(path)
                    if n > CMD_MAX:
                        errors.append(f"{shown}: {n} lines (commands stay at or under "
                                      f"{CMD_MAX} and thin)")
                for kind, inc in includes(path):
                    base = os.path.basename(inc)
                    for pat, mod in FOREIGN.items():
                        if pat.match(base):
                            errors.append(f"{shown}: includes {inc}; only lib/{mod}/ may")
                    if kind == '"' and inc.split("/")[0] in LEVEL:
                        errors.append(f"{shown}: includes the library's private {inc}")
                    if re.search(r"(_private|_pkg|core_private)\.h$", base) and \
                            not base.startswith("test"):
                        errors.append(f"{shown}: includes the private header {inc}")

    errors += public_name_errors(root)
    errors += readme_table_errors(root)

    # no circles in the include graph (depth-first search)
    state = {}

    def visit(node, stack):
        state[node] = 1
        stack.append(node)
        for nxt in graph.get(node, []):
            if state.get(nxt) == 1:
                cyc = stack[stack.index(nxt):] + [nxt]
                errors.append("include circle: " +
                              " -> ".join(os.path.relpath(p, root) for p in cyc))
            elif nxt in graph and not state.get(nxt):
                visit(nxt, stack)
        stack.pop()
        state[node] = 2

    for node in sorted(graph):
        if not state.get(node):
            visit(node, [])

    for e in errors:
        print(e)
    print(f"layout: {len(graph)} files in lib/ checked, {len(errors)} problems")
    return 1 if errors else 0


def public_name_errors(root):
    """Rule 7: each public function's family belongs to its header's module."""
    errors, owner = [], {}
    for mod, fams in FAMILIES.items():
        for fam in fams:
            if fam in owner:
                errors.append(f"FAMILIES: es_{fam}_ is owned by {owner[fam]} and {mod}")
            owner[fam] = mod
    inc = os.path.join(root, "lib", "include", "edgespace")
    for name in sorted(os.listdir(inc)) if os.path.isdir(inc) else []:
        mod = PUBLIC.get(name)
        if not mod:
            continue
        with open(os.path.join(inc, name), encoding="utf-8") as f:
            text = f.read()
        for fn in PUBLIC_FN.findall(text):
            fam = fn.split("_")[1]
            if fam not in owner:
                errors.append(f"lib/include/edgespace/{name}: {fn}: es_{fam}_ is no module's "
                              f"family (tests/layout/check_layout.py FAMILIES)")
            elif owner[fam] != mod:
                errors.append(f"lib/include/edgespace/{name}: {fn} is declared in a header of "
                              f"{mod}, but es_{fam}_ is {owner[fam]}'s")
    return errors


def readme_table_errors(root):
    """Rule 8: lib/README.md's module table against the sources."""
    errors, rows = [], []
    lib = os.path.join(root, "lib")
    readme = os.path.join(lib, "README.md")
    if not os.path.isfile(readme):
        return ["lib/README.md: missing"]
    with open(readme, encoding="utf-8") as f:
        for line in f:
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            m = re.match(r"^`([a-z0-9]+)/`$", cells[0]) if len(cells) == 4 else None
            if m:
                rows.append((m.group(1), cells[2], cells[3]))
    mods = [m for m, _, _ in rows]
    folders = sorted(d for d in os.listdir(lib) if os.path.isdir(os.path.join(lib, d))
                     and d != "include")
    for d in folders:
        if d not in mods:
            errors.append(f"lib/README.md: no row for lib/{d}/")
    for m in mods:
        if m not in LEVEL:
            errors.append(f"lib/README.md: row {m}/ is no module of the data flow")
    if [m for m in mods if m in LEVEL] != [m for m in ORDER if m in mods]:
        errors.append("lib/README.md: the rows are not in the data flow's order: " +
                      " ".join(mods))
    for mod, may, foreign in rows:
        if mod not in LEVEL:
            continue
        above = [m for m in ORDER if LEVEL[m] < LEVEL[mod]]
        text = re.sub(r"\([^)]*\)", "", may)        # "(its SPD sets)": prose
        if text.strip() in ("—", "-", ""):
            allowed = set()
        elif "all of the above" in text:
            allowed = set(above)
        elif "…" in text:
            lo, hi = [t.strip(" ,") for t in text.split("…")]
            allowed = {m for m in ORDER if LEVEL[lo] <= LEVEL[m] <= LEVEL[hi]}
        else:
            allowed = {t.strip() for t in text.split(",") if t.strip()}
        for m in sorted(allowed - set(LEVEL)):
            errors.append(f"lib/README.md: {mod}/ may call '{m}', which is no module")
        named = {name for name in README_LIBS if re.search(r"\b" + re.escape(name) + r"\b", foreign)}
        used, calls = set(), set()
        folder = os.path.join(lib, mod)
        for name in sorted(os.listdir(folder)) if os.path.isdir(folder) else []:
            if not name.endswith((".c", ".h")):
                continue
            for kind, inc in includes(os.path.join(folder, name)):
                base = os.path.basename(inc)
                for lname, pat in README_LIBS.items():
                    if kind == "<" and pat.match(base):
                        used.add(lname)
                if kind == '"':
                    tmod = PUBLIC.get(base) if inc.startswith("edgespace/") else inc.split("/")[0]
                    if tmod in LEVEL and tmod != mod:
                        calls.add(tmod)
        for lname in sorted(used - named):
            errors.append(f"lib/README.md: {mod}/ includes {lname}'s headers, which its row "
                          f"does not name")
        for lname in sorted(named - used):
            errors.append(f"lib/README.md: {mod}/'s row names {lname}, which it does not include")
        for m in sorted(calls - allowed):
            errors.append(f"lib/README.md: {mod}/ includes {m}/, which its row's 'may call' "
                          f"does not name")
    return errors


def self_test():
    """The checker finds each kind of violation in a small made-up tree."""
    import tempfile
    with tempfile.TemporaryDirectory() as d:
        def put(rel, text):
            p = os.path.join(d, rel)
            os.makedirs(os.path.dirname(p), exist_ok=True)
            with open(p, "w") as f:
                f.write(text)
        put("lib/include/edgespace/es_core.h", "")
        put("lib/include/edgespace/es_study.h", '#include "es_core.h"\n')
        put("lib/include/edgespace/es_stats.h", '#include "es_study.h"\n'     # upward
            "ES_API int es_store_rows_of(void);\nES_API int es_wobble_x(void);\n")
        put("lib/core/a.c", '#include "embed/embed_pkg.h"\n#include <cairo.h>\n')
        put("lib/embed/embed_pkg.h", "/* no guard */\n")
        put("lib/stats/s.c", '#include "edgespace/es_store.h"\n')             # numeric
        put("lib/mesh/x.h", '#include "mesh/y.h"\n')
        put("lib/mesh/y.h", '#include "mesh/x.h"\n')                          # circle
        put("lib/mesh/big.c", "x\n" * (LIB_MAX + 1))
        put("lib/README.md", "| module | owns | may call | foreign library |\n|---|---|---|---|\n"
            "| `core/` | c | — | — |\n| `embed/` | e | core | LAPACKE |\n")
        put("tools/cmd/c.c", '#include "core/core_private.h"\n' + "x\n" * CMD_MAX)
        import io
        import contextlib
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            rc = main(d)
        text = out.getvalue()
        want = ["es_study.h of study, above it", "embed/embed_pkg.h of embed, above it",
                "private to lib/embed/", "<cairo.h>", "without its #ifndef ES_MODULE_EMBED",
                "es_store.h of store", "include circle", "big.c: 801 lines",
                "private core/core_private.h", "c.c: 251 lines",
                "es_store_rows_of is declared in a header of stats, but es_store_ is store's",
                "es_wobble_x: es_wobble_ is no module's family",
                "core/ includes cairo's headers, which its row does not name",
                "embed/'s row names LAPACKE, which it does not include",
                "no row for lib/mesh/"]
        missing = [w for w in want if w not in text]
        if rc != 1 or missing:
            print(text)
            print("self-test: the checker missed", missing)
            return 1
    return 0


if __name__ == "__main__":
    if self_test():
        sys.exit(1)
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else
                  os.path.join(os.path.dirname(__file__), "..", "..")))
