//! Refinement of the 1° temperatures to a finer mesh: the [`EarthMap`] the renderer
//! looks up per pixel (paper Fig. 3b).

use crate::world::earth::EarthError;
use crate::world::earth::OlrGrid;
use crate::world::earth::interpolate_temperature_k;
use rayon::prelude::*;

use tirroi_core::sensor::BandLut;

use super::EarthMap;
use super::grid::{column_pass, lat_stencil, lon_stencil, row_pass};

impl EarthMap {
    /// The paper's refined mesh, degrees (Fig. 3b).
    pub const DEFAULT_MESH_DEG: f64 = 0.1;
    /// The finest mesh accepted, cells per degree (0.05°: 25.9 M cells, 207 MB).
    pub const MAX_CELLS_PER_DEG: usize = 20;

    /// Builds the map of `grid` at `mesh_deg` degrees per cell for the camera band
    /// `band`: Eq. 10 at the nodes, Catmull-Rom interpolation to every cell centre, band
    /// radiance per cell. Rows are built in parallel (rayon); the result does not depend
    /// on the thread count.
    ///
    /// # Errors
    /// [`EarthError::BadMesh`] unless `mesh_deg` is 1/k° for an integer k in
    /// 1..=[`EarthMap::MAX_CELLS_PER_DEG`] (1.0, 0.5, 0.25, 0.2, 0.1, 0.05, …).
    pub fn refine(grid: &OlrGrid, mesh_deg: f64, band: &BandLut) -> Result<EarthMap, EarthError> {
        let k = cells_per_degree(mesh_deg).ok_or(EarthError::BadMesh { mesh_deg })?;
        let (rows, cols) = (OlrGrid::ROWS * k, OlrGrid::COLS * k);
        let node_temps = grid.temperatures_k();
        let inv_k = 1.0 / k as f64;
        // The horizontal stencil depends on the column only.
        let lon_stencils: Vec<([usize; 4], [f64; 4])> = (0..cols)
            .map(|c| lon_stencil((c as f64 + 0.5) * inv_k))
            .collect();
        let mut radiance = vec![0.0f32; rows * cols];
        let mut temperature = vec![0.0f32; rows * cols];
        let per_row = |(r, (rad, temp)): (usize, (&mut [f32], &mut [f32]))| {
            let (lat_rows, wy) = lat_stencil((r as f64 + 0.5) * inv_k - 90.0);
            let passes: Vec<(f64, f64, f64)> = (0..OlrGrid::COLS)
                .map(|c| column_pass(&node_temps, &lat_rows, &wy, c))
                .collect();
            let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
            for ((rad, temp), (lon_cols, wx)) in
                rad.iter_mut().zip(temp.iter_mut()).zip(&lon_stencils)
            {
                let t = row_pass(wx, lon_cols.map(|c| passes[c]));
                let l = band
                    .radiance_f32(t, 1.0)
                    .map_err(|source| EarthError::Radiance { t_k: t, source })?;
                *temp = t;
                *rad = l;
                lo = lo.min(l);
                hi = hi.max(l);
            }
            Ok((lo, hi))
        };
        let min_max = radiance
            .par_chunks_mut(cols)
            .zip(temperature.par_chunks_mut(cols))
            .enumerate()
            .map(per_row)
            .try_reduce(
                || (f32::INFINITY, f32::NEG_INFINITY),
                |a, b| Ok((a.0.min(b.0), a.1.max(b.1))),
            )?;
        Ok(EarthMap {
            k,
            rows,
            cols,
            radiance,
            temperature,
            node_temps,
            min_max,
            clouds: None,
            cloud_t_scale: 1.0,
        })
    }

    /// This map with the sub-grid cloud texture `clouds` (built from the same grid):
    /// the renderer then takes every ray's temperature from it
    /// ([`CloudField::temperature_k`](super::CloudField::temperature_k)) instead of the
    /// mesh cell. Builds the whole texture now ([`CloudField::fill`](super::CloudField::fill),
    /// in parallel), so rendering only reads it.
    pub fn with_clouds(self, clouds: super::CloudField) -> EarthMap {
        clouds.fill();
        self.with_shared_clouds(std::sync::Arc::new(clouds), 1.0)
    }

    /// This map with a texture built (and filled) for another map, its temperatures
    /// times `temperature_scale` (> 0): the eclipse map of a day takes the sunlit map's
    /// texture with (eclipse factor)^¼, so each cell's flux is the sunlit one × the
    /// eclipse factor exactly, the same clouds, and the set-up is paid once per day.
    /// Does not fill `clouds` (cells still build on first use if nobody did).
    pub fn with_shared_clouds(
        mut self,
        clouds: std::sync::Arc<super::CloudField>,
        temperature_scale: f64,
    ) -> EarthMap {
        self.clouds = Some(clouds);
        self.cloud_t_scale = temperature_scale;
        self
    }

    /// The cloud texture, if the map has one.
    pub fn clouds(&self) -> Option<&super::CloudField> {
        self.clouds.as_deref()
    }

    /// Factor on the cloud texture's temperatures in this map (1 unless built by
    /// [`EarthMap::with_shared_clouds`] with another): the rendered brightness
    /// temperature is this × [`CloudField::temperature_k`](super::CloudField::temperature_k).
    pub fn cloud_temperature_scale(&self) -> f64 {
        self.cloud_t_scale
    }

    /// The mesh size, degrees per cell (1/k).
    pub fn mesh_deg(&self) -> f64 {
        1.0 / self.k as f64
    }

    /// (rows, columns) of the mesh: (180k, 360k).
    pub fn shape(&self) -> (usize, usize) {
        (self.rows, self.cols)
    }

    /// Index of the cell containing (lat, lon): clamped at the poles, wrapped in
    /// longitude; NaN or infinite coordinates give cell row/column 0.
    #[inline]
    fn cell(&self, lat_deg: f64, lon_deg: f64) -> usize {
        let k = self.k as f64;
        // `as usize` saturates: negative and NaN → 0.
        let r = (((lat_deg + 90.0) * k) as usize).min(self.rows - 1);
        // fmod only when the longitude is not already in [0, 360).
        let lon = if (0.0..360.0).contains(&lon_deg) {
            lon_deg
        } else {
            lon_deg.rem_euclid(360.0)
        };
        let c = ((lon * k) as usize).min(self.cols - 1);
        r * self.cols + c
    }

    /// Band radiance of the mesh cell containing (`lat_deg`, `lon_deg`), W m⁻² sr⁻¹.
    /// Latitude −90…90° (clamped beyond), any longitude (wrapped). Nearest cell: a mesh
    /// element is flat, as in the paper's rendered mesh. No allocation, a few flops.
    #[inline]
    pub fn radiance_w_m2_sr(&self, lat_deg: f64, lon_deg: f64) -> f32 {
        self.radiance[self.cell(lat_deg, lon_deg)]
    }

    /// Temperature of the mesh cell containing (`lat_deg`, `lon_deg`), K (same lookup
    /// as [`EarthMap::radiance_w_m2_sr`]).
    #[inline]
    pub fn temperature_k(&self, lat_deg: f64, lon_deg: f64) -> f32 {
        self.temperature[self.cell(lat_deg, lon_deg)]
    }

    /// The continuous interpolant the cells are sampled from, K: exact at the 1° nodes
    /// (see [`interpolate_temperature_k`]); NaN for NaN coordinates.
    pub fn interpolated_temperature_k(&self, lat_deg: f64, lon_deg: f64) -> f32 {
        interpolate_temperature_k(&self.node_temps, lat_deg, lon_deg).unwrap_or(f32::NAN)
    }

    /// Smallest and largest cell radiance, W m⁻² sr⁻¹ (for an auto-span display scale,
    /// as the paper's Fig. 3).
    pub fn min_max_radiance_w_m2_sr(&self) -> (f32, f32) {
        self.min_max
    }

    /// Cell temperatures, K, row-major (south → north, eastwards from 0°).
    pub fn temperatures_k(&self) -> &[f32] {
        &self.temperature
    }

    /// Cell radiances, W m⁻² sr⁻¹, row-major (south → north, eastwards from 0°).
    pub fn radiances_w_m2_sr(&self) -> &[f32] {
        &self.radiance
    }

    /// Heap memory held by the map, bytes.
    pub fn memory_bytes(&self) -> usize {
        (self.radiance.capacity() + self.temperature.capacity() + self.node_temps.capacity())
            * size_of::<f32>()
    }
}

/// k if `mesh_deg` = 1/k for an integer k in 1..=MAX (to 1e-9 relative).
pub(super) fn cells_per_degree(mesh_deg: f64) -> Option<usize> {
    if !(mesh_deg.is_finite() && mesh_deg > 0.0) {
        return None;
    }
    let k = (1.0 / mesh_deg).round();
    ((1.0..=EarthMap::MAX_CELLS_PER_DEG as f64).contains(&k) && (k * mesh_deg - 1.0).abs() < 1e-9)
        .then_some(k as usize)
}
