#!/usr/bin/env python3
"""tests/tools/test_docs.py MAN COMPLETION EDGESPACE [BUILD_ROOT] — the
generated man page and bash completion (tools/docs/) against the command
itself: bash completes the verbs and each verb's options as `VERB --help`
lists them (completion run in a real bash), the man page has a section for
every command of `edgespace --help` and renders with man(1) when it is
installed, and meson's install plan puts both where man and bash-completion
look."""
import json
import os
import re
import shutil
import subprocess
import sys


def complete(script, words):
    """COMPREPLY of the completion function for the command line `words`."""
    line = " ".join(words)
    prog = (f'source "{script}"; COMP_WORDS=({line}); COMP_CWORD={len(words) - 1}; '
            '_edgespace; printf "%s\\n" "${COMPREPLY[@]}"')
    r = subprocess.run(["bash", "-c", prog], capture_output=True, text=True, check=True)
    return r.stdout.split()


def main():
    man, comp, exe = sys.argv[1:4]
    build = sys.argv[4] if len(sys.argv) > 4 else None
    top = subprocess.run([exe, "--help"], capture_output=True, text=True, check=True).stdout
    verbs = re.findall(r"^  (\S+)\s{2,}", top.split("commands:")[1], re.M)
    assert "plot-pca" in verbs and "model" in verbs, verbs
    assert sorted(complete(comp, ["edgespace", "pl"])) == ["plot", "plot-pca"]
    assert complete(comp, ["edgespace", "mod"]) == ["model"]
    for verb in ("pca", "model", "render", "export"):
        helptext = subprocess.run([exe, verb, "--help"], capture_output=True, text=True,
                                  check=True).stdout
        listed = set(re.findall(r"^\s+(?:-\w, )?(--[a-z][a-z0-9-]*)", helptext, re.M))
        offered = set(complete(comp, ["edgespace", verb, "--"]))
        assert listed | {"--help"} == offered, (verb, listed ^ offered)
    assert complete(comp, ["edgespace", "render", "--perc"]) == ["--percentiles"]
    text = open(man, encoding="utf-8").read()
    assert text.startswith(".TH EDGESPACE 1")
    for v in verbs:
        assert f"\n.SS {v}\n" in text, v
    if shutil.which("man"):
        r = subprocess.run(["man", "-l", man], capture_output=True, text=True,
                           env=dict(os.environ, MANWIDTH="80", MANPAGER="cat", PAGER="cat"))
        assert r.returncode == 0 and "edgespace - statistical shape analysis" in r.stdout, \
            r.stderr
        assert "--percentiles P,Q" in r.stdout
    meson = shutil.which("meson")
    if build and meson:
        plan = json.loads(subprocess.run([meson, "introspect", "--installed", build],
                                         capture_output=True, text=True, check=True).stdout)
        dest = {os.path.basename(k): v for k, v in plan.items()}
        assert dest["edgespace.1"].endswith("/man1/edgespace.1"), dest.get("edgespace.1")
        assert any(v.endswith("/bash-completion/completions/edgespace")
                   for v in plan.values()), plan
    print("man page, completion and install plan: ok")


if __name__ == "__main__":
    main()
