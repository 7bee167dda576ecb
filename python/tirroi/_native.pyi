"""Typed stub of the Rust module ``tirroi._native`` (``python/src/lib.rs``). Use the
documented wrappers in ``tirroi`` rather than these calls: they check and convert
their input and return dataclasses."""

from typing import Any, Dict, List, Optional, Tuple

import numpy as np
import numpy.typing as npt

__version__: str

def methods() -> List[str]:
    """The detectors' names, in registry order (``tirroi_core::Method::ALL``)."""

def presets() -> List[Tuple[str, str]]:
    """The built-in presets: (name, one-line description)."""

class Renderer:
    """A dataset's plan and shared library, built once; frames render on demand."""

    def __init__(
        self,
        preset: Optional[str] = None,
        config: Optional[str] = None,
        count: Optional[int] = None,
        seed: Optional[int] = None,
    ) -> None: ...
    def __len__(self) -> int: ...
    def scene_toml(self) -> str:
        """The resolved scene file as TOML (``tirroi render --print-config``)."""
    @property
    def seed(self) -> int:
        """The dataset seed."""
    @property
    def name(self) -> str:
        """The dataset name."""
    def render(self, start: int, end: int) -> List[Dict[str, Any]]:
        """Frames ``start..end``: dicts with ``dn`` (uint16, H x W), ``signal``
        (float32, H x W, W m^-2), ``coverage`` (float32, H x W, 0..1) and ``record``
        (the frame's ``metadata.jsonl`` line, JSON text)."""

def detect(
    dn: npt.NDArray[np.uint16], method: str, bits: int
) -> Tuple[Optional[Tuple[int, int, int, int]], float, int, int, Optional[str]]:
    """(box (x0, y0, x1, y1) px or None, score 0..1, threshold, foreground px, the
    stage of ``auto-v2`` that gave the box or None)."""

class Tracker:
    """``auto-v2`` over a sequence of frames (the core's tracker)."""

    def __init__(self) -> None: ...
    def step(
        self, dn: npt.NDArray[np.uint16], bits: int
    ) -> Tuple[Optional[Tuple[int, int, int, int]], float, int, int, Optional[str]]:
        """The next frame: (box or None, score 0..1, threshold, foreground px, stage or
        None)."""
    def reset(self) -> None:
        """Forgets the history."""
    @property
    def prior(self) -> Optional[Tuple[int, int, int, int]]:
        """The last frame's box, or None."""

def band_radiance(
    temperature_k: npt.NDArray[np.float64],
    emissivity: npt.NDArray[np.float64],
    response: str,
) -> npt.NDArray[np.float64]:
    """Band radiance, W m^-2 sr^-1, flat, element by element (same-size inputs, K and
    emissivity)."""

def to_dn(
    temperature_k: npt.NDArray[np.float64],
    emissivity: float,
    response: str,
    range_k: Tuple[float, float],
    bits: int,
    netd_k: float,
    t_ref_k: float,
    flicker_correlation_px: float,
    seed: Optional[int],
) -> Tuple[npt.NDArray[np.uint16], float, float, float]:
    """(flat DN, gain DN per W m^-2, offset DN, total noise sigma DN)."""

def radiometric_temperature(
    dn: npt.NDArray[np.float64],
    emissivity: float,
    response: str,
    range_k: Tuple[float, float],
    bits: int,
) -> npt.NDArray[np.float64]:
    """Radiometric temperature, K, flat."""

def camera_defaults() -> Tuple[float, float, float, int]:
    """(NETD K, NETD reference temperature K, 1/f correlation px, bits)."""
