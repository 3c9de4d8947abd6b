//! The progress bar the front ends draw on the terminal during a job.

use crate::pipeline::Progress;

/// A bar of faces processed, with the patch count; hidden when quiet.
pub struct ProgressBar(indicatif::ProgressBar);

impl ProgressBar {
    /// A bar over `total_faces` faces (its length follows [`Progress::total`] once the run
    /// reports); hidden when `quiet`.
    pub fn new(quiet: bool, total_faces: usize) -> ProgressBar {
        if quiet {
            return ProgressBar(indicatif::ProgressBar::hidden());
        }
        let b = indicatif::ProgressBar::new(total_faces as u64);
        // A constant template; should it ever be refused, keep indicatif's default style.
        if let Ok(style) = indicatif::ProgressStyle::with_template(
            "{elapsed_precise} [{bar:40}] {pos}/{len} faces processed, {msg}",
        ) {
            b.set_style(style.progress_chars("=> "));
        }
        ProgressBar(b)
    }

    /// Show a run's progress after a patch.
    pub fn show(&self, p: Progress) {
        self.0.set_length(p.total as u64);
        self.0.set_position((p.total - p.unprocessed) as u64);
        self.0.set_message(format!("{} patches", p.patches));
    }

    /// Clear the bar from the terminal.
    pub fn finish(&self) {
        self.0.finish_and_clear();
    }
}
