#!/usr/bin/env python3
"""The shared-library closure of some ELF files, with some libraries cut off (for bundles that carry
a program to a machine without its packages).

Walks DT_NEEDED from the given files (names resolved with ldd, so RUNPATHs count), stops at the
libraries the machine keeps (glibc, the C++ runtime) and at the CUT ones: those are replaced by
stubs, so what only they load is left out. For each cut library, writes a C file that defines every
symbol its users import from it as a function that aborts (a stub fails loudly if it is ever
called; it must never be).

  closure.py --cut 'REGEX' --stubs DIR FILE...   -> prints the path of each library to carry, one
  per name it is loaded by (copy it under that path's file name)
"""
import argparse
import os
import re
import subprocess

KEEP = re.compile(r"^(linux-vdso|ld-linux|libc\.so|libm\.so|libpthread|libdl\.so|librt\.so|libresolv|"
                  r"libstdc\+\+|libgcc_s)")


def needed(path):
    out = subprocess.run(["readelf", "-d", path], capture_output=True, text=True).stdout
    return re.findall(r"\(NEEDED\)\s+Shared library: \[([^\]]+)\]", out)


def resolved(path):
    out = subprocess.run(["ldd", path], capture_output=True, text=True).stdout
    return {m.group(1): m.group(2) for m in re.finditer(r"^\s*(\S+) => (/\S+)", out, re.M)}


def symbols(path, defined):
    args = ["nm", "-D", "--defined-only" if defined else "--undefined-only", path]
    out = subprocess.run(args, capture_output=True, text=True).stdout
    names = set()
    for line in out.splitlines():
        parts = line.split()
        if parts:
            names.add(parts[-1].split("@")[0])
    return names


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cut", default="", help="regex of library names replaced by stubs")
    ap.add_argument("--stubs", default="", help="folder for the stubs' C files")
    ap.add_argument("files", nargs="+")
    a = ap.parse_args()
    cut = re.compile(a.cut) if a.cut else None
    where = {}
    for f in a.files:
        where.update(resolved(f))
    todo = [os.path.realpath(f) for f in a.files]
    seen, carry, users = set(), {}, {}
    while todo:
        f = todo.pop()
        if f in seen:
            continue
        seen.add(f)
        for name in needed(f):
            if KEEP.match(name):
                continue
            path = where.get(name)
            if path is None:
                where.update(resolved(f))
                path = where.get(name)
            if path is None:
                raise SystemExit("closure: %s (needed by %s) not found" % (name, f))
            if cut and cut.match(name):
                users.setdefault(name, (path, set()))[1].add(f)
                continue
            carry[name] = path  # copied under the name it is loaded by
            todo.append(os.path.realpath(path))
    for name, (path, us) in sorted(users.items()):
        wanted = set()
        for u in us:
            wanted |= symbols(u, defined=False)
        wanted &= symbols(os.path.realpath(path), defined=True)
        with open(os.path.join(a.stubs, name + ".c"), "w") as out:
            out.write("// Stub of %s for %s: aborts if any symbol is ever called.\n#include <stdlib.h>\n"
                      % (name, ", ".join(sorted(os.path.basename(u) for u in us))))
            for s in sorted(wanted):
                out.write("void %s(void) { abort(); }\n" % s)
    for name in sorted(carry):
        print(carry[name])


if __name__ == "__main__":
    main()
