//! Rendering a dataset's frames in memory, with their labels, and no file written: the
//! frames and [`ImageRecord`]s that [`write_dataset`](super::write_dataset) writes as
//! PNG and `metadata.jsonl`, for callers that want arrays (the Python package
//! `tirroi`, `python/`).
//!
//! The same plan, library and renderer as a written dataset, so frame `i` of a file and
//! seed has the DN of `NNNNNN.png` `i` of `tirroi render` with that file and seed, bit
//! for bit, whatever order or batch size the frames are asked in.

use std::ops::Range;

use rayon::prelude::*;

use super::DatasetError;
use super::images::{ImageRecord, record};
use super::library::Library;
use super::plan::{ImagePlan, plan};
use crate::imaging::render::Rendered;
use crate::world::scene::SceneFile;

/// One frame rendered in memory: the renderer's output (DN, signal, coverage, both
/// truth boxes) and the frame's line of `metadata.jsonl`.
#[derive(Debug, Clone)]
pub struct LabelledFrame {
    /// DN, signal (W m⁻²), target coverage and truth boxes.
    pub frame: Rendered,
    /// The labels and metadata `metadata.jsonl` holds for this frame.
    pub record: ImageRecord,
}

/// A scene file's plan and shared library (meshes, thermal solutions, Earth maps),
/// built once; frames are rendered from it on demand, in parallel.
pub struct FrameRenderer {
    file: SceneFile,
    plans: Vec<ImagePlan>,
    library: Library,
}

impl FrameRenderer {
    /// Plans every image of `file` and builds the library they share (the slow part
    /// of a small dataset: thermal solutions and Earth maps).
    ///
    /// # Errors
    /// [`DatasetError`] when an Earth source cannot be read or a thermal solve fails.
    pub fn new(file: SceneFile) -> Result<FrameRenderer, DatasetError> {
        let plans = plan(&file);
        let library = Library::build(&file, &plans)?;
        Ok(FrameRenderer {
            file,
            plans,
            library,
        })
    }

    /// The scene file the frames come from.
    pub fn file(&self) -> &SceneFile {
        &self.file
    }

    /// Frames in the dataset.
    pub fn len(&self) -> usize {
        self.plans.len()
    }

    /// Whether the dataset has no frame.
    pub fn is_empty(&self) -> bool {
        self.plans.is_empty()
    }

    /// Renders frames `range` (indices in the dataset, clipped to [`Self::len`]) in
    /// parallel, in index order.
    ///
    /// # Errors
    /// [`DatasetError`] naming the first image the renderer refuses.
    pub fn render(&self, range: Range<usize>) -> Result<Vec<LabelledFrame>, DatasetError> {
        let end = range.end.min(self.plans.len());
        let start = range.start.min(end);
        self.plans[start..end]
            .par_iter()
            .map(|plan| {
                let (frame, thermal) = self.library.render(&self.file, plan)?;
                let record = record(&self.file, plan, &frame, &thermal);
                Ok(LabelledFrame { frame, record })
            })
            .collect()
    }
}
