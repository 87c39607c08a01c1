//! Progress of long offline work, drawn on stderr (and not at all when stderr is not a terminal).

use indicatif::{ProgressBar, ProgressStyle};

pub struct Progress {
    bar: ProgressBar,
}

impl Progress {
    pub fn new(label: &'static str) -> Self {
        let bar = ProgressBar::new(0).with_message(label);
        // The template is a constant: it parses, or the default style is kept.
        if let Ok(style) = ProgressStyle::with_template(
            "{msg} [{bar:30}] {pos}/{len} {elapsed_precise} (eta {eta})",
        ) {
            bar.set_style(style.progress_chars("#>-"));
        }
        Self { bar }
    }

    pub fn set(&mut self, done: usize, total: usize) {
        self.bar.set_length(total as u64);
        self.bar.set_position(done as u64);
    }

    pub fn finish(&mut self) {
        self.bar.finish();
    }
}
