#!/usr/bin/env bash
# Renders the frames the firmware demo embeds (firmware/frames.toml) with the host's
# renderer and writes them to firmware/frames/ as <scene>.png (16-bit PNG, 14-bit DN)
# with truth.csv and 8-bit previews. Deterministic: the same renderer gives the same
# bytes, so a re-run only changes files when the renderer changed.
#
# Usage: scripts/flight-frames.sh [OUT]      (default OUT: firmware/frames; uses rustup's
#        `cargo run --release`). scripts/flight.sh renders to a temporary OUT and fails
#        when the committed frames differ from what the renderer makes now.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"

out="${1:-firmware/frames}"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT

cargo run --release --quiet -- render --config firmware/frames.toml --out "$tmp" --preview

# The scene names, in the order of firmware/frames.toml (one image each).
mapfile -t names < <(awk -F'"' '/^\[\[scene\]\]/ { s = 1 } s && /^name *=/ { print $2; s = 0 }' firmware/frames.toml)
rm -rf "$out"
mkdir -p "$out/preview"
{
    head -n 1 "$tmp/truth.csv"
    i=0
    tail -n +2 "$tmp/truth.csv" | while IFS= read -r line; do
        file="${line%%,*}"
        name="${names[$i]}"
        cp "$tmp/$file" "$out/$name.png"
        cp "$tmp/preview/$file" "$out/preview/$name.png"
        echo "$name.png,${line#*,}"
        i=$((i + 1))
    done
} >"$out/truth.csv"
echo "flight-frames: ${#names[@]} frames in $out: ${names[*]}"
