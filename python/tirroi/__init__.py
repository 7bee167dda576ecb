"""tirroi: synthetic thermal-infrared (TIR) frames with labels, the flight ROI
detectors and the camera model of the tirroi workspace, as NumPy arrays.

The calls go to the same Rust code as the ``tirroi`` command line (no second
renderer): ``render`` is ``tirroi render`` without files, ``detect`` is
``tirroi detect``, ``band_radiance``/``to_dn``/``radiometric_temperature`` are the
camera model of ``tirroi sensor`` and of the renderer.

Units: temperatures in K, band radiance in W m^-2 sr^-1, emissive power and the
renderer's signal in W m^-2, DN (digital numbers) as unsigned integers of ``bits``
bits, boxes in pixels as ``(x0, y0, x1, y1)`` with (x0, y0) inclusive and (x1, y1)
exclusive, x to the right and y down.

Bad input raises ``ValueError`` with the message the CLI prints after
``tirroi: error:``.

Example::

    import tirroi
    for frame in tirroi.render(preset="realistic", count=8, seed=1):
        hit = tirroi.detect(frame.dn, method="auto", bits=frame.bits)
        print(frame.index, frame.truth, hit.box, round(hit.score, 3))
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from typing import Any, Dict, Iterator, List, Optional, Sequence, Tuple, Union, overload

import numpy as np
import numpy.typing as npt

from . import _native

__all__ = [
    "Box",
    "Detection",
    "Frame",
    "Frames",
    "Tracker",
    "band_radiance",
    "dn_noise_sigma",
    "detect",
    "emissive_power",
    "methods",
    "presets",
    "radiometric_temperature",
    "render",
    "to_dn",
    "NETD_K",
    "NETD_REFERENCE_K",
    "FLICKER_CORRELATION_PX",
    "DEFAULT_BITS",
]

__version__: str = _native.__version__

Box = Tuple[int, int, int, int]
"""A box ``(x0, y0, x1, y1)`` in pixels: (x0, y0) inclusive, (x1, y1) exclusive."""

ArrayLikeFloat = Union[float, Sequence[float], npt.NDArray[Any]]
"""Numbers: a float, a sequence of floats or a NumPy array of any real dtype."""

NETD_K: float
NETD_REFERENCE_K: float
FLICKER_CORRELATION_PX: float
DEFAULT_BITS: int
NETD_K, NETD_REFERENCE_K, FLICKER_CORRELATION_PX, DEFAULT_BITS = _native.camera_defaults()
"""The camera's defaults (Hayabusa2 TIR, ``[camera]`` of a scene file): NETD (K), the
temperature the NETD is quoted at (K), the 1/f noise correlation length (px), the
DN bit depth."""


def methods() -> List[str]:
    """The detectors' names in registry order (``tirroi_core::Method::ALL``), e.g.
    ``['otsu', 'adaptive', 'wge', 'dog', 'auto', 'auto-v2']``; any of them is a ``method`` of
    :func:`detect`."""
    return list(_native.methods())


def presets() -> Dict[str, str]:
    """The built-in scene presets, name -> one-line description (``tirroi render
    --list-presets``)."""
    return dict(_native.presets())


def _box(b: Sequence[int]) -> Optional[Box]:
    """A label's box, or None for the all-zero box of a frame without a target."""
    x0, y0, x1, y1 = (int(v) for v in b)
    if x1 <= x0 or y1 <= y0:
        return None
    return (x0, y0, x1, y1)


@dataclass(frozen=True)
class Frame:
    """One rendered frame and its labels (a PNG and its lines of ``truth.csv`` and
    ``metadata.jsonl`` in a ``tirroi render`` directory).

    Attributes:
        index: position in the dataset (the CLI's file ``NNNNNN.png``).
        file: the CLI's file name, ``f"{index:06}.png"``.
        dn: uint16 array (height, width) of ``bits``-bit DN, the camera's output.
        truth: the truth box, the tight box of the pixels at least half covered by the
            target (``truth.csv``'s ``x0,y0,x1,y1``; the coverage is the scene file's
            ``truth_coverage``, 1/2 by default), or None when no target is in view.
        truth_quarter: the box of the pixels more than 1/4 covered (``*_quarter``
            columns), or None.
        signal: float32 array (height, width), the signal before the DN map, W m^-2:
            emissive power F (radiometry mode) or the flux q on the sensor (detection
            mode), after the optics PSF and the sensor signature when the scene has
            them; no noise.
        coverage: float32 array (height, width), the fraction of each pixel covered by
            the target, 0..1.
        metadata: the frame's ``metadata.jsonl`` object: ``target`` ("none" without
            one), ``range_m`` (m), ``earth_fraction`` (0..1), ``noise_sigma_dn`` (DN),
            ``signal_to_clutter``, ``visible_share`` (0..1), ``readout``,
            ``dn_gain`` (DN per W m^-2), ``dn_offset`` (DN), ``target_temperature_k``
            (K), ``mode``, ``scale``, ``illumination``, pose and seeds.
    """

    index: int
    file: str
    dn: npt.NDArray[np.uint16]
    truth: Optional[Box]
    truth_quarter: Optional[Box]
    signal: npt.NDArray[np.float32]
    coverage: npt.NDArray[np.float32]
    metadata: Dict[str, Any]

    @property
    def bits(self) -> int:
        """Bit depth of the DN (saturation at 2**bits - 1)."""
        return int(self.metadata["bits"])

    @property
    def target(self) -> str:
        """Target model (``cube-cylinder``, ``tango``, ``winged-sat``) or ``none``."""
        return str(self.metadata["target"])

    @property
    def range_m(self) -> float:
        """Camera-target centre distance, m."""
        return float(self.metadata["range_m"])

    @property
    def earth_fraction(self) -> float:
        """Fraction of the frame whose pixel centres see the Earth, 0..1."""
        return float(self.metadata["earth_fraction"])

    @property
    def noise_sigma_dn(self) -> float:
        """Total noise sigma, DN (0 without noise)."""
        return float(self.metadata["noise_sigma_dn"])


def _frame(d: Dict[str, Any]) -> Frame:
    record = json.loads(d["record"])
    return Frame(
        index=int(record["index"]),
        file=str(record["file"]),
        dn=d["dn"],
        truth=_box(record["bbox"]),
        truth_quarter=_box(record["bbox_quarter"]),
        signal=d["signal"],
        coverage=d["coverage"],
        metadata=record,
    )


class Frames(Sequence[Frame]):
    """The frames of a dataset, rendered on demand (in parallel batches, without the
    GIL) as they are iterated or indexed; ``len()`` is the number of frames. Made by
    :func:`render`. Frame ``i`` is the same, bit for bit, whatever order or batch it is
    rendered in."""

    def __init__(self, renderer: _native.Renderer, batch: int) -> None:
        self._renderer = renderer
        self._batch = batch

    def __len__(self) -> int:
        return len(self._renderer)

    @property
    def seed(self) -> int:
        """The dataset seed."""
        return int(self._renderer.seed)

    @property
    def name(self) -> str:
        """The dataset name (``[dataset] name``)."""
        return str(self._renderer.name)

    def scene_toml(self) -> str:
        """The resolved scene file as TOML (``tirroi render --print-config``): save it
        and pass it as ``render(config=...)`` or ``tirroi render --config`` to get the
        same frames."""
        return str(self._renderer.scene_toml())

    def render_range(self, start: int, stop: int) -> List[Frame]:
        """Frames ``start..stop`` (clipped to the dataset), rendered in one parallel
        batch."""
        return [_frame(d) for d in self._renderer.render(start, stop)]

    @overload
    def __getitem__(self, index: int) -> Frame: ...

    @overload
    def __getitem__(self, index: slice) -> List[Frame]: ...

    def __getitem__(self, index: Union[int, slice]) -> Union[Frame, List[Frame]]:
        n = len(self)
        if isinstance(index, slice):
            start, stop, step = index.indices(n)
            if step == 1:
                return self.render_range(start, stop)
            return [self[i] for i in range(start, stop, step)]
        i = index + n if index < 0 else index
        if not 0 <= i < n:
            raise IndexError(f"frame {index} of a dataset of {n} frames")
        return self.render_range(i, i + 1)[0]

    def __iter__(self) -> Iterator[Frame]:
        for start in range(0, len(self), self._batch):
            yield from self.render_range(start, start + self._batch)


def render(
    preset: Optional[str] = None,
    *,
    config: Optional[str] = None,
    count: Optional[int] = None,
    seed: Optional[int] = None,
    batch: int = 32,
) -> Frames:
    """Renders a dataset to arrays with labels: ``tirroi render`` without files.

    Args:
        preset: a built-in scene set (:func:`presets`: ``paper``, ``tango``,
            ``quick``, ``realistic``, ``realistic-tango``, ``realistic-approach``,
            ``realistic-winged``).
        config: or a TOML scene file (the format of ``tirroi render --print-config``).
        count: images in total, spread over the scene kinds in proportion (default: the
            preset's or file's), 1..=10 000 000; rounded per kind exactly as the CLI's
            ``--count``, so ``len()`` of the result may differ slightly.
        seed: the dataset seed (default: the preset's or file's).
        batch: frames rendered per parallel batch while iterating (memory: about
            0.8 MB per 328x248 frame).

    Returns:
        :class:`Frames`: frame ``i`` has the DN of ``NNNNNN.png`` ``i`` of
        ``tirroi render`` with the same preset or file, seed and count, and its labels.

    Raises:
        ValueError: an unknown preset, an unreadable or invalid scene file (the message
            names file, line and field), a bad count.
    """
    if (preset is None) == (config is None):
        raise ValueError("give --preset NAME or --config FILE (exactly one)")
    if batch < 1:
        raise ValueError(f"batch {batch}: expected at least 1 frame")
    if count is not None and (not isinstance(count, int) or count < 1):
        raise ValueError(f"count {count!r}: expected an integer 1..=10000000")
    if seed is not None and (not isinstance(seed, int) or not 0 <= seed < 2**64):
        raise ValueError(f"seed {seed!r}: expected an integer 0..2**64")
    renderer = _native.Renderer(
        preset=preset,
        config=None if config is None else str(config),
        count=count,
        seed=seed,
    )
    return Frames(renderer, batch)


@dataclass(frozen=True)
class Detection:
    """What a detector found in a frame (``tirroi detect --json``'s line).

    Attributes:
        method: the detector's name.
        box: the region of interest ``(x0, y0, x1, y1)``, px, or None.
        score: confidence 0..1 that the box is the target (IoU >= 0.5 with the truth);
            0 without a box. The paper's four detectors report 1 for any box.
        threshold: the detector's threshold; its unit depends on the detector (DN for
            otsu, a DN offset for adaptive, a gradient for wge, a DoG response in DN for
            dog, an edge threshold in DN for auto).
        foreground_px: pixels in the detector's mask before the box rule.
        stage: for ``auto-v2`` with a box, the stage that gave it (``tracked``,
            ``blob``, ``deep-space``, ``classifier``, ``spot`` or ``outline``: the
            ``"stage"`` of ``tirroi detect --json``); None otherwise.
    """

    method: str
    box: Optional[Box]
    score: float
    threshold: int
    foreground_px: int
    stage: Optional[str] = None


def detect(
    dn: npt.ArrayLike, method: str = "auto", bits: int = DEFAULT_BITS
) -> Detection:
    """Runs one of the flight detectors on a frame: ``tirroi detect``.

    Args:
        dn: 2-D array (height, width) of non-negative integer DN, at most 1024x768 px;
            uint16 is used as is, other integer types are checked and converted.
        method: a name from :func:`methods` (``auto`` is ours; ``otsu``, ``adaptive``,
            ``wge``, ``dog`` the paper's).
        bits: the DN bit depth, 1..=16 (14 for the TIR camera); every DN must be at
            most 2**bits - 1.

    Returns:
        :class:`Detection` with the box (or None) and its score.

    Raises:
        ValueError: an unknown method, a frame that is not 2-D or too large, DN that do
            not fit ``bits``.
    """
    box, score, threshold, foreground_px, stage = _native.detect(
        _dn_uint16(dn), str(method), _bits(bits)
    )
    return _detection(str(method), box, score, threshold, foreground_px, stage)


class Tracker:
    """``auto-v2`` over a sequence of frames: ``tirroi detect --method auto-v2 --track``.

    Each :meth:`step` takes the next frame. With a box on the last frame it tracks (a
    window around that box, and the box's own cells refined while its place looks the
    same); without one it searches the frame, and also answers a candidate under the
    confidence gate once that candidate followed itself over 3 frames while moving at
    least 2 px per frame against the ground (score 0.667): a faint target acquired by
    its motion, where clouds and hot pixels move with the ground.

    Example::

        tracker = tirroi.Tracker()
        for frame in tirroi.render(preset="realistic-approach", count=24, seed=1):
            hit = tracker.step(frame.dn, bits=frame.bits)
    """

    def __init__(self) -> None:
        self._inner = _native.Tracker()

    def step(self, dn: npt.ArrayLike, bits: int = DEFAULT_BITS) -> Detection:
        """The next frame of the sequence (as :func:`detect`'s ``dn`` and ``bits``).

        Returns:
            :class:`Detection` of ``auto-v2`` on this frame.

        Raises:
            ValueError: a frame that is not 2-D or too large, DN that do not fit ``bits``.
        """
        box, score, threshold, foreground_px, stage = self._inner.step(
            _dn_uint16(dn), _bits(bits)
        )
        return _detection("auto-v2", box, score, threshold, foreground_px, stage)

    def reset(self) -> None:
        """Forgets the history: the next frame starts a new sequence."""
        self._inner.reset()

    @property
    def prior(self) -> Optional[Box]:
        """The last frame's box (the next frame's prior), or None."""
        p = self._inner.prior
        return None if p is None else (int(p[0]), int(p[1]), int(p[2]), int(p[3]))


def _dn_uint16(dn: npt.ArrayLike) -> npt.NDArray[np.uint16]:
    """``dn`` as a C-ordered uint16 array (other integer types checked and converted)."""
    a = np.asarray(dn)
    if a.dtype != np.uint16:
        if a.dtype.kind not in "iub":
            raise ValueError(
                f"dn has dtype {a.dtype}; expected integer DN (uint16, or another integer type)"
            )
        if a.size and (int(a.min()) < 0 or int(a.max()) > 65535):
            raise ValueError(
                f"dn spans {int(a.min())}..{int(a.max())}; expected DN in 0..=65535"
            )
        a = a.astype(np.uint16)
    return np.ascontiguousarray(a)


def _bits(bits: int) -> int:
    if not isinstance(bits, (int, np.integer)) or not 1 <= int(bits) <= 16:
        raise ValueError(f"--bits: {bits} is out of range; expected an integer bit depth 1..=16")
    return int(bits)


def _detection(
    method: str,
    box: Optional[Sequence[int]],
    score: float,
    threshold: int,
    foreground_px: int,
    stage: Optional[str],
) -> Detection:
    return Detection(
        method=method,
        box=None if box is None else (int(box[0]), int(box[1]), int(box[2]), int(box[3])),
        score=float(score),
        threshold=int(threshold),
        foreground_px=int(foreground_px),
        stage=None if stage is None else str(stage),
    )


def _floats(x: ArrayLikeFloat, name: str) -> npt.NDArray[np.float64]:
    a = np.asarray(x, dtype=np.float64)
    if a.dtype.kind != "f":
        raise ValueError(f"{name}: expected numbers")
    return a


def band_radiance(
    temperature_k: ArrayLikeFloat,
    emissivity: ArrayLikeFloat = 1.0,
    response: str = "hayabusa2",
) -> npt.NDArray[np.float64]:
    """Band radiance i(T, e) = integral of e B(lambda, T) R(lambda) d lambda, in
    W m^-2 sr^-1 (paper Eqs. 1, 6), element by element: ``tirroi sensor``'s
    ``radiance_w_m2_sr``.

    Args:
        temperature_k: temperature(s), K, 0..=10 000; any shape.
        emissivity: gray-body emissivity, 0..=1, broadcast against ``temperature_k``.
        response: the camera's spectral response R: ``hayabusa2`` (the TIR's measured
            curve, the default), ``tir`` (the analytic 8-12 um model) or ``flat``
            (R = 1: i = e sigma T^4 / pi).

    Returns:
        float64 array of the broadcast shape (a 0-d array for scalars), W m^-2 sr^-1.

    Raises:
        ValueError: an unknown response, a temperature or emissivity out of range or
            not finite.
    """
    t, e = np.broadcast_arrays(_floats(temperature_k, "temperature_k"), _floats(emissivity, "emissivity"))
    out = _native.band_radiance(np.ascontiguousarray(t), np.ascontiguousarray(e), str(response))
    return np.asarray(out).reshape(t.shape)


def emissive_power(
    temperature_k: ArrayLikeFloat,
    emissivity: ArrayLikeFloat = 1.0,
    response: str = "hayabusa2",
) -> npt.NDArray[np.float64]:
    """Band emissive power F = pi i(T, e), W m^-2 (Eq. 6): the radiometry-mode signal
    the DN map takes. Arguments as :func:`band_radiance`."""
    return np.pi * band_radiance(temperature_k, emissivity, response)


def to_dn(
    temperature_k: ArrayLikeFloat,
    *,
    emissivity: float = 1.0,
    response: str = "hayabusa2",
    range_k: Tuple[float, float] = (150.0, 460.0),
    bits: int = DEFAULT_BITS,
    seed: Optional[int] = None,
    netd_k: float = NETD_K,
    t_ref_k: float = NETD_REFERENCE_K,
    flicker_correlation_px: float = FLICKER_CORRELATION_PX,
) -> npt.NDArray[np.uint16]:
    """Radiometry-mode DN of a scene of temperatures, as the core's camera model (and
    ``tirroi sensor``'s ``dn`` column) computes it: F = pi i(T, e) (W m^-2), the Eq. 17
    linear map with F(T_lo) -> DN 0 and F(T_hi) -> 2**bits - 1, rounding and saturation;
    with ``seed``, the renderer's seeded sensor noise added before quantisation.

    Args:
        temperature_k: 1-D (one row) or 2-D (height, width) temperatures, K.
        emissivity: gray-body emissivity of the scene and of the range, 0 < e <= 1.
        response: ``hayabusa2``, ``tir`` or ``flat`` (:func:`band_radiance`).
        range_k: (T_lo, T_hi), K, the auto range of Eq. 17.
        bits: DN bit depth, 1..=16.
        seed: None: no noise. An integer: Johnson, 1/f and thermal noise of the
            bolometer (Table 2 voltages) scaled so that the total sigma in DN is
            ``netd_k`` times dDN/dT at ``t_ref_k``; the same seed gives the same noise
            (the row-by-row noise field of the renderer; rows of at most 1024 px).
        netd_k: noise-equivalent temperature difference, K (the camera's, 0.4 K, by
            default).
        t_ref_k: the temperature where dDN/dT sets the noise, K.
        flicker_correlation_px: correlation length of the 1/f noise, px.

    Returns:
        uint16 array of ``temperature_k``'s shape.

    Raises:
        ValueError: a bad response, range, bit depth, emissivity or temperature.
    """
    t = _floats(temperature_k, "temperature_k")
    if t.ndim not in (1, 2):
        raise ValueError(
            f"temperature_k has {t.ndim} dimensions; expected 1 (one row) or 2 (height, width)"
        )
    if seed is not None and (not isinstance(seed, int) or not 0 <= seed < 2**64):
        raise ValueError(f"seed {seed!r}: expected an integer 0..2**64 or None")
    lo, hi = range_k
    dn, _gain, _offset, _sigma = _native.to_dn(
        np.ascontiguousarray(t),
        float(emissivity),
        str(response),
        (float(lo), float(hi)),
        int(bits),
        float(netd_k),
        float(t_ref_k),
        float(flicker_correlation_px),
        seed,
    )
    return np.asarray(dn).reshape(t.shape)


def dn_noise_sigma(
    *,
    emissivity: float = 1.0,
    response: str = "hayabusa2",
    range_k: Tuple[float, float] = (150.0, 460.0),
    bits: int = DEFAULT_BITS,
    netd_k: float = NETD_K,
    t_ref_k: float = NETD_REFERENCE_K,
) -> float:
    """The total noise sigma, DN, that :func:`to_dn` adds with these arguments and a
    seed (``tirroi sensor``'s ``noise.total_dn`` at the ``netd`` level)."""
    _dn, _gain, _offset, sigma = _native.to_dn(
        np.full((1, 1), float(t_ref_k)),
        float(emissivity),
        str(response),
        (float(range_k[0]), float(range_k[1])),
        int(bits),
        float(netd_k),
        float(t_ref_k),
        float(FLICKER_CORRELATION_PX),
        0,
    )
    return float(sigma)


def radiometric_temperature(
    dn: ArrayLikeFloat,
    *,
    emissivity: float = 1.0,
    response: str = "hayabusa2",
    range_k: Tuple[float, float] = (150.0, 460.0),
    bits: int = DEFAULT_BITS,
) -> npt.NDArray[np.float64]:
    """Radiometric temperature of radiometry-mode DN, K: the T whose pi e i(T) maps to
    each DN under the Eq. 17 map of :func:`to_dn` (``tirroi sensor``'s ``t_rad_k``);
    0 at or below DN 0's signal. Any shape; arguments as :func:`to_dn`."""
    d = _floats(dn, "dn")
    lo, hi = range_k
    out = _native.radiometric_temperature(
        np.ascontiguousarray(d).reshape(-1), float(emissivity), str(response), (float(lo), float(hi)), int(bits)
    )
    return np.asarray(out).reshape(d.shape)
