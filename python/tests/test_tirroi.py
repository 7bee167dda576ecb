"""The Python package against the `tirroi` binary's own outputs: the same frames
(DN, both truth boxes, metadata) as `tirroi render`, the same boxes and scores as
`tirroi detect --json` (and `--track` for the tracker), the same camera model as `tirroi sensor --json`, and the CLI's
error messages.

The binary is $TIRROI_BIN when set, else this checkout's release build, brought up
to date with `cargo build --release` first (a no-op when it is), so a stale binary is never
compared. PNGs are decoded with Pillow, not with the Rust reader under test.
"""

from __future__ import annotations

import csv
import json
import math
import os
import subprocess
from pathlib import Path
from typing import Any, Dict, List, Optional, Tuple

import numpy as np
import pytest
from PIL import Image

import tirroi

REPO = Path(__file__).resolve().parents[2]

# Small datasets: the realistic world (real camera
# signature, PSF, clouds, no-target frames, 12-16 bit) and the paper-like quick preset.
DATASETS = [("realistic", 6, 1), ("quick", 5, 3)]


@pytest.fixture(scope="session")
def tirroi_bin() -> Path:
    env = os.environ.get("TIRROI_BIN")
    if env:
        return Path(env)
    # Release, as the CI's flight step builds it (a no-op there): the realistic world's
    # library (signature pool, cloud maps) takes minutes in a debug build.
    subprocess.run(
        ["cargo", "build", "--release", "-q", "-p", "tirroi-host", "--bin", "tirroi"],
        cwd=REPO,
        check=True,
    )
    exe = REPO / "target" / "release" / "tirroi"
    assert exe.is_file(), exe
    return exe


def run(bin: Path, *args: str, ok: bool = True) -> subprocess.CompletedProcess[str]:
    p = subprocess.run([str(bin), *args], capture_output=True, text=True)
    if ok:
        assert p.returncode == 0, p.stderr
    return p


def cli_error(bin: Path, *args: str) -> str:
    """The CLI's one-line error message (without `tirroi: error: `); exit code 2."""
    p = run(bin, *args, ok=False)
    assert p.returncode == 2, (p.returncode, p.stderr)
    line = p.stderr.strip().splitlines()[-1]
    prefix = "tirroi: error: "
    assert line.startswith(prefix), line
    return line[len(prefix) :]


@pytest.fixture(scope="session")
def cli_datasets(tirroi_bin: Path, tmp_path_factory: pytest.TempPathFactory) -> Dict[str, Path]:
    out = {}
    for preset, count, seed in DATASETS:
        d = tmp_path_factory.mktemp(preset)
        run(tirroi_bin, "render", "--preset", preset, "--count", str(count), "--seed", str(seed), "--out", str(d))
        out[preset] = d
    return out


def truth_rows(d: Path) -> List[Dict[str, str]]:
    with open(d / "truth.csv", newline="") as f:
        return list(csv.DictReader(f))


def csv_box(row: Dict[str, str], suffix: str = "") -> Optional[Tuple[int, int, int, int]]:
    fields = [row[k + suffix] for k in ("x0", "y0", "x1", "y1")]
    if all(v == "" for v in fields):
        return None
    x0, y0, x1, y1 = (int(v) for v in fields)
    return (x0, y0, x1, y1)


def png(path: Path) -> np.ndarray:
    with Image.open(path) as im:
        assert im.mode in ("I;16", "I;16B", "I"), im.mode
        return np.array(im, dtype=np.int64).astype(np.uint16)


@pytest.mark.parametrize("preset,count,seed", DATASETS)
def test_render_equals_cli(cli_datasets: Dict[str, Path], preset: str, count: int, seed: int) -> None:
    d = cli_datasets[preset]
    rows = truth_rows(d)
    meta = [json.loads(line) for line in (d / "metadata.jsonl").read_text().splitlines()]
    frames = tirroi.render(preset=preset, count=count, seed=seed, batch=4)
    assert len(frames) == len(rows) == len(meta)
    assert frames.seed == seed
    targets = set()
    for frame, row, m in zip(frames, rows, meta):
        assert frame.file == row["file"] == m["file"]
        expected = png(d / row["file"])
        assert frame.dn.dtype == np.uint16
        assert frame.dn.shape == expected.shape
        np.testing.assert_array_equal(frame.dn, expected)
        assert frame.truth == csv_box(row)
        assert frame.truth_quarter == csv_box(row, "_quarter")
        assert frame.metadata == m
        assert frame.bits == int(row["bits"])
        assert frame.target == row["target"]
        assert int(frame.dn.max()) <= 2**frame.bits - 1
        assert frame.signal.shape == frame.coverage.shape == frame.dn.shape
        assert frame.signal.dtype == frame.coverage.dtype == np.float32
        assert float(frame.coverage.min()) >= 0.0 and float(frame.coverage.max()) <= 1.0
        if frame.truth is None:
            # No pixel half covered.
            assert float(frame.coverage.max()) < 0.5
        else:
            x0, y0, x1, y1 = frame.truth
            inside = frame.coverage[y0:y1, x0:x1]
            assert float(inside.max()) >= 0.5
            outside = frame.coverage.copy()
            outside[y0:y1, x0:x1] = 0.0
            assert float(outside.max()) < 0.5
        targets.add(frame.target)
    if preset == "realistic":
        # The realistic world has no-target frames too; both must come through.
        assert "none" in targets and len(targets) > 1, targets


def test_frames_do_not_depend_on_order_or_batch() -> None:
    frames = tirroi.render(preset="quick", count=5, seed=3, batch=2)
    all_at_once = frames.render_range(0, len(frames))
    for i in reversed(range(len(frames))):
        one = frames[i]
        np.testing.assert_array_equal(one.dn, all_at_once[i].dn)
        assert one.metadata == all_at_once[i].metadata
    assert [f.index for f in frames[1:4]] == [1, 2, 3]
    assert frames[-1].index == len(frames) - 1
    with pytest.raises(IndexError):
        frames[len(frames)]


def test_scene_file_gives_the_same_frames(tmp_path: Path, tirroi_bin: Path) -> None:
    frames = tirroi.render(preset="quick", count=5, seed=3)
    path = tmp_path / "scene.toml"
    path.write_text(frames.scene_toml())
    # The TOML is the CLI's own --print-config.
    printed = run(tirroi_bin, "render", "--preset", "quick", "--count", "5", "--seed", "3", "--print-config").stdout
    assert frames.scene_toml() == printed
    again = tirroi.render(config=str(path))
    assert len(again) == len(frames)
    for a, b in zip(frames, again):
        np.testing.assert_array_equal(a.dn, b.dn)
        assert a.truth == b.truth and a.metadata == b.metadata


def frames_by_bits(preset: str, count: int, seed: int) -> Dict[int, List[tirroi.Frame]]:
    """The frames of a preset, grouped by bit depth (one `tirroi detect --bits` call
    each), in file order."""
    by_bits: Dict[int, List[tirroi.Frame]] = {}
    for f in tirroi.render(preset=preset, count=count, seed=seed):
        by_bits.setdefault(f.bits, []).append(f)
    return by_bits


def test_detect_equals_cli(cli_datasets: Dict[str, Path], tirroi_bin: Path) -> None:
    methods = tirroi.methods()
    assert "auto" in methods and len(set(methods)) == len(methods)
    for preset, count, seed in DATASETS:
        d = cli_datasets[preset]
        for bits, group in frames_by_bits(preset, count, seed).items():
            files = [str(d / f.file) for f in group]
            out = run(tirroi_bin, "detect", "--json", "--method", "all", "--bits", str(bits), *files).stdout
            lines = [json.loads(line) for line in out.splitlines()]
            assert len(lines) == len(group) * len(methods)
            # `--method all` runs the registry in order: the same names as methods().
            assert [line["method"] for line in lines[: len(methods)]] == methods
            for k, line in enumerate(lines):
                frame = group[k // len(methods)]
                assert line["file"].endswith(frame.file)
                got = tirroi.detect(frame.dn, method=line["method"], bits=bits)
                want_box = None if line["bbox"] is None else tuple(line["bbox"])
                assert got.box == want_box, (frame.file, line)
                assert got.method == line["method"]
                # The CLI prints the f32 score through JSON; the same f32 here.
                assert np.float32(got.score) == np.float32(line["score"]), (frame.file, line)
                # `auto-v2` names the stage that gave its box, as the CLI does.
                assert got.stage == line.get("stage"), (frame.file, line)
                assert (got.stage is not None) == (got.method == "auto-v2" and got.box is not None)
                if got.box is None:
                    assert got.score == 0.0


def test_tracker_equals_cli(cli_datasets: Dict[str, Path], tirroi_bin: Path) -> None:
    """`tirroi.Tracker` steps as `tirroi detect --method auto-v2 --track` over the same
    files in the same order (frames of one bit depth: one sequence each), and forgets
    its history on `reset`."""
    for preset, count, seed in DATASETS:
        d = cli_datasets[preset]
        for bits, group in frames_by_bits(preset, count, seed).items():
            files = [str(d / f.file) for f in group]
            out = run(
                tirroi_bin, "detect", "--json", "--method", "auto-v2", "--track",
                "--bits", str(bits), *files,
            ).stdout
            lines = [json.loads(line) for line in out.splitlines()]
            assert len(lines) == len(group)
            tracker = tirroi.Tracker()
            for frame, line in zip(group, lines):
                got = tracker.step(frame.dn, bits=bits)
                want_box = None if line["bbox"] is None else tuple(line["bbox"])
                assert got.box == want_box, (frame.file, line)
                assert np.float32(got.score) == np.float32(line["score"]), (frame.file, line)
                assert got.stage == line.get("stage"), (frame.file, line)
                assert tracker.prior == got.box
            tracker.reset()
            assert tracker.prior is None
            first = tracker.step(group[0].dn, bits=bits)
            assert first == tirroi.detect(group[0].dn, "auto-v2", bits=bits)


def test_detect_takes_other_integer_arrays() -> None:
    frame = tirroi.render(preset="quick", count=5, seed=3)[0]
    a = tirroi.detect(frame.dn, "otsu", bits=frame.bits)
    b = tirroi.detect(frame.dn.astype(np.int32), "otsu", bits=frame.bits)
    c = tirroi.detect(np.asfortranarray(frame.dn), "otsu", bits=frame.bits)
    assert a == b == c


def sensor(tirroi_bin: Path, *args: str) -> Dict[str, Any]:
    rep: Dict[str, Any] = json.loads(run(tirroi_bin, "sensor", "--json", *args).stdout)
    return rep


TEMPS = [150.0, 200.0, 250.0, 300.0, 350.0, 400.0, 460.0, 173.25, 1000.0]


@pytest.mark.parametrize("response", ["hayabusa2", "tir", "flat"])
@pytest.mark.parametrize("emissivity", [1.0, 0.83])
def test_camera_model_equals_sensor(tirroi_bin: Path, response: str, emissivity: float) -> None:
    temps = ",".join(repr(t) for t in TEMPS)
    rep = sensor(
        tirroi_bin, "--response", response, "--temps", temps, "--emissivity", repr(emissivity),
        "--bits", "14", "--range-k", "150,460",
    )
    rows = rep["temperatures"]
    t = np.array(TEMPS)
    i = tirroi.band_radiance(t, emissivity, response=response)
    assert i.shape == t.shape and i.dtype == np.float64
    # The same f64 code: equal to the last bit (serde_json prints round-trip floats).
    assert i.tolist() == [r["radiance_w_m2_sr"] for r in rows]
    assert tirroi.emissive_power(t, emissivity, response=response).tolist() == pytest.approx(
        [r["emissive_power_w_m2"] for r in rows], rel=1e-15
    )
    dn = tirroi.to_dn(t, emissivity=emissivity, response=response, range_k=(150.0, 460.0), bits=14)
    assert dn.dtype == np.uint16
    assert dn.tolist() == [r["dn"] for r in rows]
    t_rad = tirroi.radiometric_temperature(dn, emissivity=emissivity, response=response, range_k=(150.0, 460.0), bits=14)
    assert t_rad.tolist() == [r["t_rad_k"] for r in rows]
    if response == "flat":
        # Closed form: i = e sigma T^4 / pi.
        sigma = 5.670374419e-8
        np.testing.assert_allclose(i, emissivity * sigma * t**4 / math.pi, rtol=1e-9)


def test_band_radiance_broadcasts() -> None:
    t = np.linspace(150.0, 460.0, 12).reshape(3, 4)
    e = np.array([1.0, 0.9, 0.8, 0.7])
    i = tirroi.band_radiance(t, e)
    assert i.shape == (3, 4)
    for r in range(3):
        for c in range(4):
            assert i[r, c] == tirroi.band_radiance(float(t[r, c]), float(e[c]))
    assert tirroi.band_radiance(300.0).shape == ()
    # Monotonic in T and linear in e.
    assert np.all(np.diff(tirroi.band_radiance(t.ravel())) > 0)
    np.testing.assert_allclose(tirroi.band_radiance(300.0, 0.5), 0.5 * tirroi.band_radiance(300.0), rtol=1e-12)


def test_noise_is_seeded_and_has_the_sensor_sigma(tirroi_bin: Path) -> None:
    rep = sensor(tirroi_bin, "--level", "netd", "--bits", "14", "--range-k", "150,460", "--netd-k", "0.4", "--t-ref-k", "300")
    sigma = tirroi.dn_noise_sigma(bits=14, range_k=(150.0, 460.0), netd_k=0.4, t_ref_k=300.0)
    assert sigma == pytest.approx(rep["noise"]["total_dn"], rel=1e-6)
    scene = np.full((256, 256), 300.0)
    clean = tirroi.to_dn(scene, netd_k=0.4)
    a = tirroi.to_dn(scene, seed=7, netd_k=0.4)
    b = tirroi.to_dn(scene, seed=7, netd_k=0.4)
    c = tirroi.to_dn(scene, seed=8, netd_k=0.4)
    np.testing.assert_array_equal(a, b)
    assert np.any(a != c)
    diff = a.astype(np.float64) - clean.astype(np.float64)
    # 65 536 samples: the measured sigma within 10 % (the 1/f part is correlated along
    # rows and columns, so fewer independent samples than pixels), the mean near 0.
    assert float(diff.std()) == pytest.approx(sigma, rel=0.10)
    assert abs(float(diff.mean())) < 0.2 * sigma
    # About 0.4 K of noise at 300 K: sigma / (dDN/dT) is the NETD.
    assert rep["noise"]["netd_equivalent_k"] == pytest.approx(0.4, rel=1e-6)


def test_errors_are_value_errors_with_the_cli_message(tirroi_bin: Path, tmp_path: Path) -> None:
    msg = cli_error(tirroi_bin, "render", "--preset", "nope", "--out", str(tmp_path / "x"))
    with pytest.raises(ValueError) as e:
        tirroi.render(preset="nope")
    assert str(e.value) == msg
    bad = tmp_path / "bad.toml"
    bad.write_text("[[scene]]\ncount = 4\nrange_m = \"far\"\n")
    msg = cli_error(tirroi_bin, "render", "--config", str(bad), "--out", str(tmp_path / "y"))
    with pytest.raises(ValueError) as e:
        tirroi.render(config=str(bad))
    assert str(e.value) == msg
    missing = tmp_path / "missing.toml"
    msg = cli_error(tirroi_bin, "render", "--config", str(missing), "--out", str(tmp_path / "z"))
    with pytest.raises(ValueError) as e:
        tirroi.render(config=str(missing))
    assert str(e.value) == msg
    msg = cli_error(tirroi_bin, "sensor", "--response", "nope")
    with pytest.raises(ValueError) as e:
        tirroi.band_radiance(300.0, response="nope")
    assert str(e.value) == msg
    msg = cli_error(tirroi_bin, "sensor", "--range-k", "400,300")
    with pytest.raises(ValueError) as e:
        tirroi.to_dn([300.0], range_k=(400.0, 300.0))
    assert str(e.value) == msg
    frame = np.zeros((8, 8), dtype=np.uint16)
    with pytest.raises(ValueError, match="unknown method `nope`"):
        tirroi.detect(frame, method="nope")
    with pytest.raises(ValueError, match="2-D frame"):
        tirroi.detect(np.zeros((2, 8, 8), dtype=np.uint16))
    with pytest.raises(ValueError, match="above 2\\^12 - 1"):
        tirroi.detect(np.full((8, 8), 5000, dtype=np.uint16), bits=12)
    with pytest.raises(ValueError):
        tirroi.detect(np.full((8, 8), -1, dtype=np.int32))
    with pytest.raises(ValueError):
        tirroi.detect(np.zeros((8, 8)), method="auto")
    with pytest.raises(ValueError):
        tirroi.band_radiance(-5.0)
    with pytest.raises(ValueError):
        tirroi.band_radiance(float("nan"))
    with pytest.raises(ValueError):
        tirroi.render(preset="quick", count=0)
    with pytest.raises(ValueError):
        tirroi.render()


def test_presets_and_methods_are_the_clis(tirroi_bin: Path) -> None:
    listed = run(tirroi_bin, "render", "--list-presets").stdout.splitlines()
    names = [line.split()[0] for line in listed if line.strip()]
    assert list(tirroi.presets()) == names
    assert {"paper", "quick", "realistic"} <= set(names)


def test_any_array_layout_gives_the_same_numbers() -> None:
    t = np.linspace(150.0, 460.0, 12).reshape(3, 4)
    for view in (np.asfortranarray(t), t.T.copy().T, t[:, ::-1][:, ::-1]):
        np.testing.assert_array_equal(tirroi.band_radiance(view), tirroi.band_radiance(t))
        np.testing.assert_array_equal(tirroi.to_dn(view), tirroi.to_dn(t))
