#!/usr/bin/env python3
"""tests/tools/test_options.py EDGESPACE README CLI_OPTIONS_C — the one option
vocabulary (README "Options", issue 29) against the command itself.

Oracles: the README table is the specification of the new names; the table of
old spellings in tools/cli_options.c is parsed independently of the C code
that applies it; every old spelling is checked against its new one by running
both and comparing what they write (byte for byte) where the option has an
effect a test can see, and by the one deprecation line otherwise."""
import os
import re
import subprocess
import sys
import tempfile

EXE, README, ALIASES_C = sys.argv[1:4]
failures = []


def check(ok, what):
    if not ok:
        failures.append(what)
        print("FAIL:", what)


def run(*args, cwd=None, ok=True):
    r = subprocess.run([EXE, *args], capture_output=True, text=True, cwd=cwd)
    if ok and r.returncode != 0:
        raise SystemExit(f"edgespace {' '.join(args)} failed ({r.returncode}): {r.stderr}")
    return r


def verbs():
    top = run("--help").stdout
    return re.findall(r"^  (\S+)\s{2,}", top.split("commands:")[1], re.M)


def help_options(verb):
    """{long name: short letter or None} as VERB --help lists them."""
    out = run(verb, "--help").stdout
    opts = {}
    for m in re.finditer(r"^\s+(?:-(\w), )?--([a-z][\w-]*)", out, re.M):
        opts[m.group(2)] = m.group(1)
    return opts


def readme_table():
    text = open(README).read().split("## Options", 1)[1].split("\n## ", 1)[0]
    rows = []
    for line in text.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) != 3 or not cells[1].startswith("`-"):
            continue
        m = re.match(r"`(?:-(\w), )?--([\w-]+)", cells[1])
        main, _, longonly = cells[2].partition("(long only:")
        cmds = [c.strip() for c in main.split(",")]
        lo = [c.strip() for c in longonly.rstrip(")").split(",")] if longonly else []
        rows.append((cells[0], m.group(1), m.group(2), cmds, lo))
    return rows


def alias_table():
    src = open(ALIASES_C).read()
    return [(v.split(), old, new, None if meta == "NULL" else meta.strip('"'))
            for v, old, new, meta in re.findall(
                r'\{"([a-z -]+)", "(-[-\w]+)", "(--[\w-]+)", ("[A-Z]+"|NULL)\}', src)]


def main():
    allv = verbs()
    helps = {v: help_options(v) for v in allv}

    # one meaning per short letter across every command's --help
    letter = {}
    for v, opts in helps.items():
        for name, short in opts.items():
            if short and short != "h":
                prev = letter.setdefault(short, (name, v))
                check(prev[0] == name, f"-{short} is --{prev[0]} in {prev[1]} but --{name} in {v}")

    # the README table: each concept's option in each command it names
    table = readme_table()
    check(len(table) >= 10, "README Options table parsed")
    for concept, short, name, cmds, longonly in table:
        for v in cmds + longonly:
            check(v in helps, f"README names command {v}")
            opts = helps.get(v, {})
            check(name in opts, f"{v} --help lists --{name} ({concept})")
            want = short if v in cmds else None
            check(opts.get(name) == want, f"{v} --{name}: short -{opts.get(name)}, README -{want}")

    # no old spelling in any --help, each one works and warns once
    aliases = alias_table()
    check(len(aliases) >= 30, "alias table parsed")
    for vs, old, new, meta in aliases:
        for v in vs:
            check(v in helps, f"alias verb {v} exists")
            opts = helps.get(v, {})
            if old.startswith("--"):
                check(old[2:] not in opts or old == "--csv" and v == "ingest-landmarks",
                      f"{v} --help still lists {old}")
            else:
                check(old[1] not in opts.values(), f"{v} --help still lists {old}")
            check(new[2:] in opts, f"{v}: {old}'s new spelling {new} is an option")
            args = [v, "--help", old] + (["X"] if meta else [])
            r = run(*args)
            line = (f"edgespace {v}: {old}{' ' + meta if meta else ''} is now "
                    f"{new}{' ' + meta if meta else ''}; the old spelling will go")
            check(r.stderr.splitlines() == [line], f"{' '.join(args)}: stderr {r.stderr!r}")

    with tempfile.TemporaryDirectory() as d:
        behaviour(d)
    if failures:
        raise SystemExit(f"{len(failures)} failures")
    print("ok")


def same_files(a, b, what):
    check(open(a, "rb").read() == open(b, "rb").read(), what)


def behaviour(d):
    # synth: -n/--n (count) and -s (seed) against --count/--seed
    r = run("synth", "tube", "-o", f"{d}/old", "-n", "5", "-s", "7")
    check(r.stderr.count("is now") == 2, f"synth old spellings warn: {r.stderr!r}")
    run("synth", "tube", "-o", f"{d}/new", "--count", "5", "--seed", "7")
    check(sorted(os.listdir(f"{d}/old")) == sorted(os.listdir(f"{d}/new")), "synth files")
    for f in os.listdir(f"{d}/new"):
        same_files(f"{d}/old/{f}", f"{d}/new/{f}", f"synth -n/-s: {f}")
    # a manifest with a group, so a second PCA differs from the first
    lines = open(f"{d}/new/manifest.csv").read().splitlines()
    with open(f"{d}/new/m.csv", "w") as f:
        f.write(lines[0] + ",group\n")
        for i, l in enumerate(lines[1:]):
            f.write(f"{l},{'a' if i < 4 else 'b'}\n")
    st = f"{d}/st.h5"
    r = run("ingest", st, "-m", f"{d}/new/m.csv", "-q")
    check("-m CSV is now --manifest CSV" in r.stderr, "ingest -m warns")
    run("pca", st, "-n", "all", "-k", "3")
    run("pca", st, "-n", "some", "--components", "2", "--where", "group=a")

    # --csv (old) and --output (new) write the same table; twice warns once
    r = run("point", st, "-p", "all", "--csv", f"{d}/p_old.csv", "--csv", f"{d}/p_old.csv",
            "mean + pc:1")
    check(r.stderr.count("--csv PATH is now --output PATH") == 1, f"warns once: {r.stderr!r}")
    run("point", st, "-p", "all", "--output", f"{d}/p_new.csv", "mean + pc:1")
    same_files(f"{d}/p_old.csv", f"{d}/p_new.csv", "point --csv = --output")
    # a unique prefix of a new long name is still getopt's
    run("point", st, "--pc", "all", "--out", f"{d}/p_pre.csv", "mean + pc:1")
    same_files(f"{d}/p_pre.csv", f"{d}/p_new.csv", "point --pc/--out prefixes")

    # pc:NAME:K is pc:K with --pca NAME (the established form, tests/stats)
    run("point", st, "-p", "some", "-o", f"{d}/k1.csv", "mean + 2*pc:1")
    run("point", st, "-p", "all", "-o", f"{d}/k2.csv", "mean + 2*pc:some:1")
    run("point", st, "-o", f"{d}/k3.csv", "mean + 2*pc:some:1 - pc:all:2 + pc:all:2")
    same_files(f"{d}/k1.csv", f"{d}/k2.csv", "pc:some:1 = --pca some pc:1")
    run("point", st, "-p", "all", "-o", f"{d}/k4.csv", "mean + 2*pc:1")
    check(open(f"{d}/k1.csv").read() != open(f"{d}/k4.csv").read(), "the two PCAs differ")
    r = run("point", st, "mean + pc:nope:1", ok=False)
    check(r.returncode == 1 and "pc:nope:1" in r.stderr and re.search(r"'(all|some)'", r.stderr),
          f"unknown PCA named with what exists: {r.stderr!r}")
    r = run("point", st, "pc:all", ok=False)
    check(r.returncode == 1 and "pc:NAME:K" in r.stderr, f"pc:all: {r.stderr!r}")

    # embed --init mean[FILTER] (the point syntax's filter) is mean:FILTER
    meshes = []
    for i, init in enumerate(["mean[group=a]", "mean:group=a"]):
        out = f"{d}/init{i}.obj"
        r = run("embed", st, "--point", "row:" + lines[1].split(",")[0].removesuffix(".obj"),
                "--init", init, "-o", out, "--no-store", ok=False)
        check(r.returncode == 0, f"embed --init {init}: {r.stderr!r}")
        meshes.append(open(out, "rb").read() if r.returncode == 0 else b"")
        check(r.returncode != 0 or "4 rows" in r.stdout, f"--init {init} uses group a: {r.stdout!r}")
    check(meshes[0] == meshes[1], "embed --init mean[group=a] = mean:group=a")
    r = run("embed", st, "--point", "mean", "--init", "mean[group=a", "-o", f"{d}/x.obj",
            "--no-store", ok=False)
    check(r.returncode == 1 and "]" in r.stderr, f"mean[ unclosed: {r.stderr!r}")

    # export --select / -s (old) and --where (new)
    run("export", st, "--select", "group=b", "--lengths", f"{d}/l_old.csv")
    run("export", st, "-s", "group=b", "--lengths", f"{d}/l_old2.csv")
    run("export", st, "--where", "group=b", "--lengths", f"{d}/l_new.csv")
    same_files(f"{d}/l_old.csv", f"{d}/l_new.csv", "export --select = --where")
    same_files(f"{d}/l_old2.csv", f"{d}/l_new.csv", "export -s = --where")

    # results -k (old) and --kind
    old = run("results", st, "-k", "pca").stdout
    check(old == run("results", st, "--kind", "pca").stdout and "pca/some" in old, "results -k")

    # an old letter inside a cluster is refused with its new spelling
    r = run("compare", st, "-g", "x", "-qp", "5", ok=False)
    check(r.returncode == 2 and "--permutations" in r.stderr, f"-qp: {r.stderr!r}")

    # plot STORE --pca: plot-pca's figure, with one line naming plot-pca
    r = subprocess.run([EXE, "plot", st, "--pca", "all", "-o", f"{d}/f.svg"],
                       capture_output=True, text=True)
    if r.returncode == 0 or "cairo" not in r.stderr:
        check("is now plot-pca" in r.stderr, f"plot --pca warns: {r.stderr!r}")


if __name__ == "__main__":
    main()
