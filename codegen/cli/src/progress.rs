//! The progress shown on long commands: a bar where the fraction done is known (`verify`,
//! `simulate`), a spinner with the elapsed time where it is not (deriving closed forms).

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

/// Runs `work` under a spinner on stderr (hidden when stderr is not a terminal) that shows
/// `label` and the elapsed time, ticking from its own thread so that it moves while `work`
/// computes: deriving a long or oblique chain's closed forms can take many seconds. Cleared
/// afterwards.
pub(crate) fn with_spinner<T>(label: &str, work: impl FnOnce() -> T) -> T {
    with_stages(label, |_| work())
}

/// [`with_spinner`] for work in stages: `work` gets a callback that changes the spinner's
/// label to what it does now (deriving, then building with cargo).
pub(crate) fn with_stages<T>(label: &str, work: impl FnOnce(&mut dyn FnMut(&str)) -> T) -> T {
    let spinner = indicatif::ProgressBar::new_spinner();
    spinner.set_style(
        indicatif::ProgressStyle::with_template("{spinner} {msg} {elapsed}")
            .expect("static template"),
    );
    spinner.set_message(label.to_string());
    spinner.enable_steady_tick(std::time::Duration::from_millis(120));
    let result = work(&mut |stage: &str| spinner.set_message(stage.to_string()));
    spinner.finish_and_clear();
    result
}
