//! Signals the model follows, below it: scalar [`TimeHistory`] records, a block's
//! [`BaseMotion`] (its translations following histories: an accelerogram on a shaking table, a
//! recorded ground velocity) and [`LoadHistory`] (a wrench scaled by a history). The model
//! evaluates them every step (`model/excitation.rs`); [`crate::loading`] re-exports them beside
//! the drivers that use them (servo, push-over).

mod base_motion;
mod load_history;
mod time_history;

pub use base_motion::{BaseMotion, MotionKind};
pub use load_history::LoadHistory;
pub use time_history::TimeHistory;
