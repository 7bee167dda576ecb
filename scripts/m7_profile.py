"""Attributes the M7 execution counts of scripts/m7-profile.sh to functions, to
`auto-v2`'s stages and to source lines.

Usage: python3 scripts/m7_profile.py ELF BLOCKS CALLS
BLOCKS: lines "address executions instructions" (hex address of a translated block);
CALLS: the number of whole-frame `auto-v2` calls the run made (the per-call figures
divide by it).
"""
import collections
import os
import subprocess
import sys

# The first match along a block's inline chain (innermost first) names its stage.
STAGES = [
    ("full_block", "cell plane"), ("edge_block", "cell plane"), ("block_of", "cell plane"),
    ("fill_cells", "cell plane"),
    ("full_inner_cell", "cell plane"), ("cell_row", "cell plane"),
    ("score_reaching", "forest"), ("leaf_of", "forest"),
    ("sub_window_extremes", "4x4 windows"), ("cell_features", "cell features"),
    ("is_seed", "cascade"), ("prescreen::", "cascade"),
    ("levels", "levels"), ("select_binned", "levels"),
    ("difference_sigma", "noise"), ("noise_sigma", "noise"),
    ("integrate", "integrals"), ("blob", "saturated blob"), ("saturated", "saturated blob"),
    ("deep_space", "deep space"), ("smooth::", "deep space"), ("small", "small target"),
    ("spot", "spot"), ("body::", "stages 5-8"), ("half_max", "stages 5-8"),
    ("refine", "stages 5-8"), ("finish", "stages 5-8"),
    ("rate_component", "rating"), ("shape::", "rating"), ("most_confident", "rating"),
    ("strongest_component", "components"), ("label_edge_cells", "components"),
]


def chains(elf, addresses):
    """Inline chain (function, file:line), innermost first, per block address."""
    out = subprocess.run(
        ["arm-none-eabi-addr2line", "-e", elf, "-f", "-i", "-C", "-a"]
        + ["0x" + a for a in addresses],
        capture_output=True, text=True, check=True,
    ).stdout.split("\n")
    result, cur, i = {}, None, 0
    while i < len(out):
        line = out[i]
        if line.startswith("0x"):
            cur = int(line, 16)
            result[cur] = []
            i += 1
        elif line and i + 1 < len(out):
            result[cur].append((line, out[i + 1].split(" (")[0]))
            i += 2
        else:
            i += 1
    return result


def main():
    elf, blocks, calls = sys.argv[1], sys.argv[2], float(sys.argv[3])
    rows = []
    for line in open(blocks):
        f = line.split()
        if len(f) == 3:
            rows.append((f[0], int(f[1]), int(f[2])))
    chain_of = chains(elf, [r[0] for r in rows])
    total = sum(c * n for _, c, n in rows)
    outer = collections.Counter()
    stage = collections.Counter()
    line_of = collections.Counter()
    for address, count, length in rows:
        chain = chain_of.get(int(address, 16), [])
        if not chain:
            continue
        w = count * length
        outer[chain[-1][0][:110]] += w
        names = " ".join(fn for fn, _ in chain)
        if "AutoV2" not in names and "learned" not in names:
            continue
        label = next(
            (s for fn, _ in chain for key, s in STAGES if key in fn), "other auto-v2"
        )
        stage[label] += w
        root = os.getcwd() + "/"
        ours = next((fl for _, fl in chain if fl.startswith(root)), chain[0][1])
        line_of[(label, ours.replace(root, ""))] += w
    print(f"whole run: {total / 1e6:.1f} M instructions")
    print("\n== functions (outermost, inlined code included), whole run")
    for name, w in outer.most_common(20):
        print(f"{w / 1e6:9.2f} M  {name}")
    print(f"\n== auto-v2 by stage, per whole-frame call ({calls:g} calls)")
    s = sum(stage.values())
    for name, w in stage.most_common():
        print(f"{w / calls / 1e6:7.3f} M  {100 * w / s:5.1f} %  {name}")
    print(f"{s / calls / 1e6:7.3f} M  total")
    print("\n== auto-v2's hottest source lines, per call")
    for (label, fl), w in line_of.most_common(25):
        print(f"{w / calls / 1e6:7.3f} M  {label:14s} {fl}")


if __name__ == "__main__":
    main()
