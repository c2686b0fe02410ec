//! Progress bars for long runs (indicatif). They draw on standard error and hide themselves when
//! it is not a terminal (CI logs, pipes), so they cost nothing there.

pub use indicatif::{MultiProgress, ProgressBar};

/// A progress bar of `len` units with a message, an elapsed time and an estimate of the time left.
///
/// ```
/// let bar = voussoir_arch::progress::bar(100, "settling");
/// bar.inc(10);
/// bar.finish_and_clear();
/// ```
pub fn bar(len: u64, message: &str) -> ProgressBar {
    let bar = ProgressBar::new(len);
    if let Ok(style) =
        indicatif::ProgressStyle::with_template("{msg:>24} [{elapsed_precise}] {wide_bar} {percent:>3}% (eta {eta})")
    {
        bar.set_style(style);
    }
    bar.set_message(message.to_owned());
    bar
}
