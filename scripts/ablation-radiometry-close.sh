#!/usr/bin/env bash
# What each realism factor of the `realistic` preset costs `auto-v2` on radiometry at
# close range (issue 16; docs/detectors.md § Session 35): the preset's radiometry-close
# scene rendered as it is, with one factor turned back to the paper world's, and with
# the four camera/Earth factors off and then one scene factor more, COUNT frames each
# from SEED (the same seed for every variant), scored by `auto_v2_cells predict` and
# the mean IoU of the frames with a target (½ truth, `tirroi eval`) printed per variant.
#
#   scripts/ablation-radiometry-close.sh [COUNT] [SEED] [OUT_DIR]
#
# Defaults: 200 frames, seed 7301 (family A's seed range), /tmp/ablation. About 15 s of
# rendering and 5 s of scoring per variant on 2 cores (release build).
set -euo pipefail
count=${1:-200}
seed=${2:-7301}
out=${3:-/tmp/ablation}
cd "$(dirname "$0")/.."
cargo build --release -q -p tirroi-host --bin tirroi --example auto_v2_cells
tirroi=target/release/tirroi
predict=target/release/examples/auto_v2_cells
mkdir -p "$out"
"$tirroi" render --preset realistic --print-config > "$out/realistic.toml"
python3 - "$out" <<'PY'
import re, sys
out = sys.argv[1]
text = open(f"{out}/realistic.toml").read()
# The [dataset]/[camera]/[earth_model] head and the radiometry-close scene alone.
head, rest = text.split("[[scene]]", 1)
scenes = ["[[scene]]" + s for s in rest.split("[[scene]]")]
base = head + next(s for s in scenes if 'name = "radiometry-close"' in s)

def fixed(s, table, line):
    """A `[scene.TABLE]` range replaced by one value."""
    s, n = re.subn(r"\[scene\." + table + r"\]\nmin = [^\n]*\nmax = [^\n]*\n", "", s)
    assert n == 1, table
    return s.replace("no_target_fraction", line + "\nno_target_fraction", 1)

def sub(s, old, new):
    assert old in s, old
    return s.replace(old, new, 1)

texture = lambda s: sub(s, 'texture = "clouds"', 'texture = "paper"')
signature = lambda s: sub(s, 'signature = "hayabusa2-dark"\n', "")
psf = lambda s: sub(s, "optics_psf = true", "optics_psf = false")
readout = lambda s: sub(s, 'readout = ["auto", "fixed-gain"]', 'readout = ["auto"]')
offset = lambda s: sub(s, "max_offset_fraction = 1.2", "max_offset_fraction = 0.6")
gain = lambda s: fixed(s, "gain", "gain = 1.0")
noise = lambda s: fixed(s, "noise_netd_factor", "noise_netd_factor = 1.0")
bits = lambda s: sub(s, "bits = [12, 14, 16]\n", "")
moon = lambda s: re.sub(r"\[scene\.moon\]\nprobability = [^\n]*\n", "", s)
camera_off = lambda s: readout(psf(signature(texture(s))))
variants = {
    "realistic": base,
    "offset-0.6": offset(base),
    "smooth-earth": texture(base),
    "no-signature": signature(base),
    "noise-1": noise(base),
    "auto-readout": readout(base),
    "gain-1": gain(base),
    "no-psf": psf(base),
    "camera-earth-off": camera_off(base),
    "camera-earth-off+offset-0.6": offset(camera_off(base)),
    "camera-earth-off+gain-noise-1": noise(gain(camera_off(base))),
    "camera-earth-off+bits-14": bits(camera_off(base)),
    "camera-earth-off+no-moon": moon(camera_off(base)),
    "paper-like": moon(bits(noise(gain(offset(camera_off(base)))))),
}
with open(f"{out}/variants.txt", "w") as f:
    for name, s in variants.items():
        open(f"{out}/{name}.toml", "w").write(s)
        # The saturated blob's cut: 2 px with the optics PSF, 0 without (detectors.md).
        f.write(f"{name} {2 if 'optics_psf = true' in s else 0}\n")
PY
printf '| variant | frames with a target | auto-v2 mean IoU (½) |\n|---|---|---|\n'
while read -r name erode; do
    rm -rf "${out:?}/$name" "${out:?}/$name-eval"
    "$tirroi" render --config "$out/$name.toml" --count "$count" --seed "$seed" --out "$out/$name" > /dev/null 2>&1
    "$predict" predict "$out/$name" "$out/$name.csv" 0 "$erode" > /dev/null 2>&1
    # The mean IoU of the frames with a target, ½ truth: `tirroi eval`'s "all" row.
    "$tirroi" eval --images "$out/$name" --method none --predictions "v2=$out/$name.csv" \
        --out "$out/$name-eval" > /dev/null 2>&1
    awk -F, -v n="$name" '$1 == "v2" && $2 == "all" { printf "| %s | %s | %.3f |\n", n, $10, $5 }' \
        "$out/$name-eval/summary.csv"
done < "$out/variants.txt"
