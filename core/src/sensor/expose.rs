//! One pass from a frame of signal to the noisy camera frame of DN (Eq. 18):
//! DN_camera = quantise(a·s + b + noise), row by row, with no buffer beyond the output.
//!
//! The noise is added before quantisation, as the A/D converter sees the analog noise;
//! quantising first and adding sub-DN noise afterwards would need a second rounding and
//! would erase the `PaperLiteral` level entirely instead of dithering it.

use super::SensorError;
use super::dn::DnMapping;
use super::noise::NoiseField;
use crate::capacity::FrameCapacity;
use crate::frame::MAX_FRAME_SIDE;

/// Converts `signal` (row-major, `width` columns: F(T) in W m⁻² for radiometry mode, q_fc
/// in W m⁻² for detection mode) to DN in `out` through `mapping`, adding `noise` when
/// given (skipped when it is silent), quantising with saturation (NaN signal gives 0).
///
/// # Errors
/// [`SensorError::BadSize`] when `width` is 0 or above [`MAX_FRAME_SIDE`], `signal`
/// and `out` differ in length or are not whole rows, there are more than
/// [`MAX_FRAME_SIDE`] rows, or the noise field's width differs. The pass keeps no
/// buffer, so only the noise field's capacity `C` bounds the width further.
pub fn expose_frame<C: FrameCapacity>(
    signal: &[f32],
    width: usize,
    mapping: &DnMapping,
    noise: Option<&mut NoiseField<C>>,
    out: &mut [u16],
) -> Result<(), SensorError> {
    if width == 0 || width > MAX_FRAME_SIDE {
        return Err(SensorError::BadSize {
            name: "width",
            actual: width,
            expected: MAX_FRAME_SIDE,
        });
    }
    if out.len() != signal.len() {
        return Err(SensorError::BadSize {
            name: "out",
            actual: out.len(),
            expected: signal.len(),
        });
    }
    if signal.len() % width != 0 || signal.len() / width > MAX_FRAME_SIDE {
        return Err(SensorError::BadSize {
            name: "signal",
            actual: signal.len(),
            expected: width * MAX_FRAME_SIDE,
        });
    }
    let gain = mapping.gain_dn() as f32;
    // + 0.5 folds the rounding of `quantise` into the offset.
    let offset = mapping.offset_dn() as f32 + 0.5;
    let max = u32::from(mapping.max_dn());
    let quantise = |dn: f32| (dn as u32).min(max) as u16;
    let rows = signal.chunks_exact(width).zip(out.chunks_exact_mut(width));
    match noise.filter(|n| !n.is_silent()) {
        None => {
            for (s_row, o_row) in rows {
                for (o, &s) in o_row.iter_mut().zip(s_row) {
                    *o = quantise(gain * s + offset);
                }
            }
        }
        Some(field) => {
            if field.width() != width {
                return Err(SensorError::BadSize {
                    name: "noise width",
                    actual: field.width(),
                    expected: width,
                });
            }
            for (s_row, o_row) in rows {
                field.combine_row(s_row, o_row, |s, n| quantise(gain * s + offset + n));
            }
        }
    }
    Ok(())
}
