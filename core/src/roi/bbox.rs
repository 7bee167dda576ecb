//! Axis-aligned boxes on the pixel grid, with the project's convention (also the
//! labels' and the CLI's, see `docs/architecture.md`): x right, y down, 0-based,
//! `[x0, y0, x1, y1]` with (x0, y0) inclusive and (x1, y1) exclusive.

/// An axis-aligned box `[x0, y0, x1, y1]` in pixels: x right, y down, 0-based,
/// (x0, y0) inclusive and (x1, y1) exclusive.
///
/// A box with `x1 <= x0` or `y1 <= y0` is empty: its area is 0, and the IoU of an
/// empty box with anything (itself included) is 0.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Roi {
    /// First column inside the box.
    pub x0: u16,
    /// First row inside the box.
    pub y0: u16,
    /// First column right of the box (exclusive).
    pub x1: u16,
    /// First row below the box (exclusive).
    pub y1: u16,
}

impl Roi {
    /// The canonical empty box.
    pub const EMPTY: Roi = Roi::new(0, 0, 0, 0);

    /// The box `[x0, y0, x1, y1]` (exclusive ends).
    pub const fn new(x0: u16, y0: u16, x1: u16, y1: u16) -> Self {
        Roi { x0, y0, x1, y1 }
    }

    /// The 1×1 box of pixel (x, y).
    pub const fn pixel(x: u16, y: u16) -> Self {
        Roi::new(x, y, x.saturating_add(1), y.saturating_add(1))
    }

    /// True when the box holds no pixel.
    pub const fn is_empty(&self) -> bool {
        self.x1 <= self.x0 || self.y1 <= self.y0
    }

    /// Width in pixels (0 when empty).
    pub const fn width(&self) -> u16 {
        if self.is_empty() {
            0
        } else {
            self.x1 - self.x0
        }
    }

    /// Height in pixels (0 when empty).
    pub const fn height(&self) -> u16 {
        if self.is_empty() {
            0
        } else {
            self.y1 - self.y0
        }
    }

    /// Area in pixels (0 when empty).
    pub const fn area(&self) -> u32 {
        self.width() as u32 * self.height() as u32
    }

    /// True when pixel (x, y) lies inside the box.
    pub const fn contains(&self, x: u16, y: u16) -> bool {
        x >= self.x0 && x < self.x1 && y >= self.y0 && y < self.y1
    }

    /// Row `y` of the box's filled mask into `row` (pixel x of the row at `row[x]`):
    /// true inside the box, false elsewhere; the box is cut to the row's length.
    pub fn fill_mask_row(&self, y: usize, row: &mut [bool]) {
        row.fill(false);
        if self.contains(self.x0, y.min(usize::from(u16::MAX)) as u16) {
            let x1 = usize::from(self.x1).min(row.len());
            if let Some(inside) = row.get_mut(usize::from(self.x0).min(x1)..x1) {
                inside.fill(true);
            }
        }
    }

    /// True when `other` lies entirely inside `self` (an empty `other` always does).
    pub const fn contains_roi(&self, other: &Roi) -> bool {
        other.is_empty()
            || (other.x0 >= self.x0
                && other.y0 >= self.y0
                && other.x1 <= self.x1
                && other.y1 <= self.y1)
    }

    /// The pixels both boxes hold ([`Roi::EMPTY`] when they do not overlap).
    pub fn intersection(&self, other: &Roi) -> Roi {
        let r = Roi::new(
            self.x0.max(other.x0),
            self.y0.max(other.y0),
            self.x1.min(other.x1),
            self.y1.min(other.y1),
        );
        if r.is_empty() { Roi::EMPTY } else { r }
    }

    /// The smallest box holding both (an empty box contributes nothing).
    pub fn hull(&self, other: &Roi) -> Roi {
        match (self.is_empty(), other.is_empty()) {
            (true, true) => Roi::EMPTY,
            (true, false) => *other,
            (false, true) => *self,
            (false, false) => Roi::new(
                self.x0.min(other.x0),
                self.y0.min(other.y0),
                self.x1.max(other.x1),
                self.y1.max(other.y1),
            ),
        }
    }

    /// Intersection over union in [0, 1]; 0 when both boxes are empty.
    ///
    /// Exact up to one f32 rounding: areas are at most 2^32 and are divided once.
    pub fn iou(&self, other: &Roi) -> f32 {
        let inter = self.intersection(other).area() as u64;
        let union = self.area() as u64 + other.area() as u64 - inter;
        if union == 0 {
            0.0
        } else {
            (inter as f64 / union as f64) as f32
        }
    }

    /// The box cut to a `width` × `height` frame ([`Roi::EMPTY`] when nothing is left).
    pub fn clip(&self, width: u16, height: u16) -> Roi {
        self.intersection(&Roi::new(0, 0, width, height))
    }

    /// `[x0, y0, x1, y1]`, the order of `truth.csv` and of the CLI's JSON.
    pub const fn to_array(&self) -> [u16; 4] {
        [self.x0, self.y0, self.x1, self.y1]
    }
}

#[cfg(test)]
mod tests {
    use super::Roi;

    #[test]
    fn mask_rows_are_the_box_pixel_by_pixel() {
        let mut row = [true; 12];
        for roi in [
            Roi::new(2, 1, 7, 4),
            Roi::new(9, 0, 30, 2), // wider than the row: cut
            Roi::new(5, 5, 3, 8),  // empty
            Roi::EMPTY,
        ] {
            for y in 0..6 {
                roi.fill_mask_row(y, &mut row);
                for (x, &m) in row.iter().enumerate() {
                    assert_eq!(m, roi.contains(x as u16, y as u16), "{roi:?} ({x}, {y})");
                }
            }
        }
    }

    #[test]
    fn area_iou_and_clip() {
        let a = Roi::new(0, 0, 4, 4);
        let b = Roi::new(2, 2, 6, 6);
        assert_eq!(a.area(), 16);
        assert_eq!(a.intersection(&b), Roi::new(2, 2, 4, 4));
        assert_eq!(a.hull(&b), Roi::new(0, 0, 6, 6));
        // 4 / (16 + 16 − 4)
        assert!((a.iou(&b) - 4.0 / 28.0).abs() < 1e-7);
        assert_eq!(a.iou(&b), b.iou(&a));
        assert_eq!(a.iou(&a), 1.0);
        assert_eq!(Roi::EMPTY.iou(&Roi::EMPTY), 0.0);
        assert_eq!(b.clip(5, 3), Roi::new(2, 2, 5, 3));
        assert_eq!(b.clip(2, 2), Roi::EMPTY);
        assert!(Roi::new(3, 1, 3, 5).is_empty());
        assert_eq!(Roi::new(5, 5, 2, 2).area(), 0);
    }
}
