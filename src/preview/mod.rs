//! `voltex preview`: a window showing a scene, rebuilt whenever a file it depends on changes.
//! `session` is the reload machinery (headless, tested on its own), [`watch`] the file watcher.

pub(crate) mod camera_file;
pub(crate) mod curves;
pub(crate) mod difference;
pub(crate) mod editor;
pub(crate) mod gui;
pub(crate) mod items;
pub(crate) mod knobs;
pub mod latency;
pub(crate) mod looks;
pub(crate) mod measure_ui;
pub(crate) mod panel;
pub(crate) mod pick;
pub mod present;
pub mod scene_text;
pub(crate) mod session;
pub(crate) mod tooltips;
pub mod watch;
pub mod window;

pub use session::{Outcome, Session};
pub use watch::Watcher;
