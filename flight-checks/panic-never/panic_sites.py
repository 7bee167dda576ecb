#!/usr/bin/env python3
"""Names the panic sites left in a tirroi-panic-never ELF linked with undefined
symbols ignored (scripts/panic-never.sh does this only after the real link failed).

From the disassembly (arm-none-eabi-objdump -d -C) it builds the direct call graph
(bl / b / b.w / conditional branches to another function's address), marks every
function from which the panic handler (`rust_begin_unwind`) is reachable, and prints
each branch from one of tirroi's functions into such a function: the branching
function, the panic it leads to, and the source line of the branch with its inline
chain (arm-none-eabi-addr2line -i), innermost tirroi frame first.

Only direct branches are seen; an indirect call (function pointer, `dyn`) that reaches
a panic is missed here, but the link check itself still fails on it.

Usage: panic_sites.py ELF   (prints one block per site; exit 0)
"""
import os
import re
import subprocess
import sys
from collections import defaultdict

# The repository root: frames in its core/ and firmware/ sources are "ours".
REPO = os.path.realpath(os.path.join(os.path.dirname(__file__), "..", ".."))
PANIC_ROOT = "rust_begin_unwind"
# `_start` is the check's entry: a component called straight from it (auto-v2) is
# inlined into it, so its branches are ours too (addr2line's chain names the source).
OURS = ("tirroi_core::", "tirroi_firmware::", "tirroi_panic_never::", "<tirroi_core::", "<tirroi_firmware::", "_start")
FUNC_RE = re.compile(r"^([0-9a-f]+) <(.+)>:$")
BRANCH_RE = re.compile(r"^\s*([0-9a-f]+):\s+(b|bl|b\.w|b\.n|b[a-z]{2}(?:\.[wn])?)\s+([0-9a-f]+) <(.+?)(\+0x[0-9a-f]+)?>")


def main() -> int:
    elf = sys.argv[1]
    dis = subprocess.run(
        ["arm-none-eabi-objdump", "-d", "-C", "--no-show-raw-insn", elf],
        check=True, capture_output=True, text=True,
    ).stdout
    calls = defaultdict(set)        # function -> called functions
    sites = defaultdict(list)       # function -> [(address, callee)]
    current = None
    for line in dis.splitlines():
        m = FUNC_RE.match(line)
        if m:
            current = m.group(2)
            continue
        m = BRANCH_RE.match(line)
        if m and current is not None:
            callee, offset = m.group(4), m.group(5)
            if callee != current and offset is None:
                calls[current].add(callee)
                sites[current].append((m.group(1), callee))
    callers = defaultdict(set)
    for f, cs in calls.items():
        for c in cs:
            callers[c].add(f)
    reach = set()
    todo = [f for f in set(calls) | set(callers) if PANIC_ROOT in f]
    while todo:
        f = todo.pop()
        if f in reach:
            continue
        reach.add(f)
        todo.extend(callers[f])
    found = 0
    seen = set()
    for f in sorted(calls):
        if not f.startswith(OURS):
            continue
        for addr, callee in sites[f]:
            if callee not in reach or callee.startswith(OURS):
                continue
            chain = subprocess.run(
                ["arm-none-eabi-addr2line", "-i", "-f", "-C", "-e", elf, addr],
                check=True, capture_output=True, text=True,
            ).stdout.splitlines()
            frames = [(chain[i], chain[i + 1]) for i in range(0, len(chain) - 1, 2)]
            ours = [
                (fn.split("::<")[0], fl[len(REPO) + 1 :])
                for fn, fl in frames
                if fl.startswith((REPO + "/core/src/", REPO + "/firmware/src/"))
            ]
            key = (ours[0] if ours else (f, "?"), callee.split("::")[-1])
            if key in seen:
                continue
            seen.add(key)
            found += 1
            (fn, fl), kind = key
            path = " <- ".join(n for n, _ in ours[1:4])
            print(f"{fl:28} {fn} [{kind}]" + (f"  (in {path})" if path else ""))
    if found == 0:
        print("no direct branch from tirroi code into a panic path (an indirect call may be the cause)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
