#!/usr/bin/env python3
"""Checks that optique's libraries follow their layers.

Reads the layers file the build writes (one line per library: NAME FOLDER: DEPS
| OUTSIDE LIBRARIES, from optique_library() in CMakeLists.txt) and fails, naming file and line, when
  - the libraries' dependencies form a cycle, or
  - a source file includes a header of a library its own library does not
    depend on (directly or through others).
So the layering in docs/architecture.md is what the build does, and stays so.

  check_layers.py LAYERS_FILE SOURCE_DIR
"""
import os
import re
import sys


def read_layers(path):
    libraries = {}  # name -> (folder, [deps])
    with open(path) as f:
        for line in f:
            line = line.strip()
            if not line:
                continue
            head, _, rest = line.partition(":")
            deps = rest.partition("|")[0]  # after '|': outside libraries
            name, folder = head.split()
            libraries[name] = (folder, deps.split())
    return libraries


def find_cycle(libraries):
    state = {}  # name -> "visiting" | "done"

    def visit(name, trail):
        if state.get(name) == "done":
            return None
        if state.get(name) == "visiting":
            return trail[trail.index(name):] + [name]
        state[name] = "visiting"
        for dep in libraries[name][1]:
            if dep not in libraries:
                return [name, dep + " (not a library)"]
            cycle = visit(dep, trail + [name])
            if cycle:
                return cycle
        state[name] = "done"
        return None

    for name in libraries:
        cycle = visit(name, [])
        if cycle:
            return cycle
    return None


def closure(libraries, name):
    seen = set()
    stack = [name]
    while stack:
        for dep in libraries[stack.pop()][1]:
            if dep not in seen:
                seen.add(dep)
                stack.append(dep)
    return seen


def main():
    if len(sys.argv) != 3:
        print(__doc__.strip().splitlines()[-1].strip(), file=sys.stderr)
        return 2
    libraries = read_layers(sys.argv[1])
    source_dir = sys.argv[2]
    cycle = find_cycle(libraries)
    if cycle:
        print("the libraries depend on each other in a cycle: " + " → ".join(cycle))
        return 1

    # Which library a header belongs to, by the path it is included with.
    owner_of_prefix = {}
    for name, (folder, _) in libraries.items():
        prefix = folder[len("common/"):] if folder.startswith("common/") else folder
        owner_of_prefix[prefix] = name
    owner_of_prefix["optique"] = "proto"  # generated: "optique/wire.pb.h"

    def owner(header):
        parts = header.split("/")[:-1]
        while parts:  # the longest folder prefix: "node/gl/x.h" is node_gl's
            found = owner_of_prefix.get("/".join(parts))
            if found:
                return found
            parts.pop()
        return None

    folders = {folder: name for name, (folder, _) in libraries.items() if folder != "proto"}
    include = re.compile(r'^\s*#\s*include\s+"([^"]+)"')
    problems = []
    checked = 0
    for folder, name in sorted(folders.items()):
        allowed = closure(libraries, name) | {name}
        root = os.path.join(source_dir, folder)
        for entry in sorted(os.listdir(root)):
            if not entry.endswith((".h", ".cpp")):
                continue
            path = os.path.join(root, entry)
            checked += 1
            with open(path) as f:
                for number, line in enumerate(f, 1):
                    m = include.match(line)
                    if not m:
                        continue
                    used = owner(m.group(1))
                    if used is None or used in allowed:
                        continue
                    problems.append(f"{folder}/{entry}:{number}: includes \"{m.group(1)}\" of library '{used}', "
                                    f"which '{name}' does not depend on (it may use: {', '.join(sorted(allowed))})")
    for p in problems:
        print(p)
    if problems:
        return 1
    print(f"{len(libraries)} libraries, acyclic; {checked} files include only what their library depends on")
    return 0


if __name__ == "__main__":
    sys.exit(main())
