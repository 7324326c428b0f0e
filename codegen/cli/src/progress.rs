//! The progress bar of long commands (`verify`, `simulate`).

/// Runs `work` with a progress callback (fraction done in [0, 1]) that drives a bar on stderr
/// labelled `label` (hidden when stderr is not a terminal); the bar is cleared afterwards.
pub(crate) fn with_progress<T>(label: &str, work: impl FnOnce(&mut dyn FnMut(f64)) -> T) -> T {
    const TICKS: u64 = 1000;
    let bar = indicatif::ProgressBar::new(TICKS);
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{msg:>12} [{bar:40}] {percent:>3}% {elapsed_precise} eta {eta}",
        )
        .expect("static template")
        .progress_chars("=> "),
    );
    bar.set_message(label.to_string());
    let result = work(&mut |f: f64| bar.set_position((f.clamp(0.0, 1.0) * TICKS as f64) as u64));
    bar.finish_and_clear();
    result
}
