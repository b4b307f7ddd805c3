//! `voltex preview`: a window showing a scene, rebuilt whenever a file it depends on changes.
//! [`session`] is the reload machinery (headless, tested on its own), [`watch`] the file watcher.

pub mod camera_file;
pub mod curves;
pub mod editor;
pub mod gui;
pub mod knobs;
pub mod panel;
pub mod present;
pub mod scene_text;
pub mod session;
pub mod watch;
pub mod window;

pub use session::{Outcome, Session};
pub use watch::Watcher;
