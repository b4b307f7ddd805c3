//! The panel's edits of the scene file: each one checked (the preview rebuilds from the edited
//! text, and an edit it cannot build is refused), then written back at its span, atomically, with
//! undo and redo. The file stays the single source of truth: when it changes on disk while the
//! panel holds an edit not yet written, the file wins and the panel says so.

use std::path::{Path, PathBuf};

use super::scene_text::{Edit, Step};
use crate::error::Result;

pub(crate) struct Editor {
    pub(crate) path: PathBuf,
    /// The file's text as last read or written here.
    disk: String,
    /// The text the preview shows: `disk` plus any edit not written (a drag in progress, or a
    /// read-only file).
    text: String,
    undo: Vec<Edit>,
    redo: Vec<Edit>,
    /// The drag in progress, as one edit from its start to now.
    gesture: Option<Edit>,
    /// For the panel: what happened to the last edit, or to the file.
    pub(crate) note: Option<String>,
    /// A refused edit: the value's path and why (the panel highlights that field).
    pub(crate) refused: Option<(Vec<Step>, String)>,
    /// The file could not be written (read-only): edits stay here.
    pub(crate) read_only: bool,
}

/// Whether an edit goes into the undo history or the redo history.
#[derive(Clone, Copy, PartialEq, Eq)]
enum History {
    New,
    Undo,
    Redo,
}

impl Editor {
    pub(crate) fn open(path: &Path) -> Result<Self> {
        let text = read(path)?;
        Ok(Editor {
            path: path.to_path_buf(),
            disk: text.clone(),
            text,
            undo: Vec::new(),
            redo: Vec::new(),
            gesture: None,
            note: None,
            refused: None,
            read_only: false,
        })
    }

    pub(crate) fn text(&self) -> &str {
        &self.text
    }

    /// Whether the panel holds an edit the file does not have.
    pub(crate) fn unsaved(&self) -> bool {
        self.text != self.disk
    }

    pub(crate) fn can_undo(&self) -> bool {
        !self.undo.is_empty() || self.gesture.is_some()
    }

    pub(crate) fn can_redo(&self) -> bool {
        !self.redo.is_empty()
    }

    /// Makes `edit` (`live`: a step of a drag, written when the drag ends). `build` is asked to
    /// render the edited text and says why it cannot; then the edit is refused: nothing changes,
    /// the field is marked. Returns whether the edit was made.
    pub(crate) fn edit(
        &mut self,
        edit: Edit,
        live: bool,
        build: impl FnOnce(&str) -> std::result::Result<(), String>,
    ) -> bool {
        self.make(edit, live, History::New, build)
    }

    fn make(
        &mut self,
        edit: Edit,
        live: bool,
        history: History,
        build: impl FnOnce(&str) -> std::result::Result<(), String>,
    ) -> bool {
        let text = match edit.apply(&self.text) {
            Ok(t) => t,
            Err(e) => {
                self.note = Some(e.to_string());
                return false;
            }
        };
        if let Err(why) = build(&text) {
            self.refused = Some((edit.path.clone(), why));
            return false;
        }
        self.refused = None;
        self.note = None;
        self.text = text;
        match history {
            History::New => {
                self.redo.clear();
                // A drag is one edit: from the value before it to the value it ends on.
                match &mut self.gesture {
                    Some(g) if g.path == edit.path => g.after = edit.after,
                    _ => {
                        self.end_gesture_history();
                        self.gesture = Some(edit);
                    }
                }
                if !live {
                    self.end_gesture_history();
                }
            }
            // The histories hold edits forwards: undo applies the inverse.
            History::Undo => self.redo.push(edit.inverse()),
            History::Redo => self.undo.push(edit),
        }
        if !live {
            self.save();
        }
        true
    }

    /// The drag ended: its edit goes into the history and the text into the file.
    pub(crate) fn end_gesture(&mut self) {
        if self.gesture.is_some() {
            self.end_gesture_history();
            self.save();
        }
    }

    fn end_gesture_history(&mut self) {
        if let Some(g) = self.gesture.take() {
            if g.before != g.after {
                self.undo.push(g);
            }
        }
    }

    /// Undoes the last edit (checked and built like any edit); false when there is none or it
    /// cannot be undone (the value changed in the file since: the note says so).
    pub(crate) fn undo(&mut self, build: impl FnOnce(&str) -> std::result::Result<(), String>) -> bool {
        self.end_gesture_history();
        let Some(e) = self.undo.pop() else { return false };
        let ok = self.make(e.inverse(), false, History::Undo, build);
        if !ok {
            self.undo.push(e);
        }
        ok
    }

    pub(crate) fn redo(&mut self, build: impl FnOnce(&str) -> std::result::Result<(), String>) -> bool {
        let Some(e) = self.redo.pop() else { return false };
        let ok = self.make(e.clone(), false, History::Redo, build);
        if !ok {
            self.redo.push(e);
        }
        ok
    }

    /// Writes the text into the file, unless the file is read-only (then the panel says so and
    /// the edits stay here until it is writable again).
    fn save(&mut self) {
        if !self.unsaved() {
            return;
        }
        match super::scene_text::write(&self.path, &self.text) {
            Ok(()) => {
                self.disk = self.text.clone();
                if self.read_only {
                    self.note = Some(format!("written to {} (writable again)", self.path.display()));
                }
                self.read_only = false;
            }
            Err(e) => {
                self.read_only = true;
                self.note = Some(e.to_string());
            }
        }
    }

    /// The file changed on disk (the watcher said so): re-reads it. Returns whether the text the
    /// preview shows changed; our own writes come back as unchanged. An unsaved edit is dropped:
    /// the file wins.
    pub(crate) fn reload(&mut self) -> bool {
        let Ok(now) = read(&self.path) else { return false };
        if now == self.disk {
            // Ours, or a touch; a read-only file may have become writable.
            if self.read_only && self.unsaved() && !readonly(&self.path) {
                self.read_only = false;
                self.save();
            }
            return false;
        }
        if self.unsaved() {
            self.note = Some(format!(
                "{} changed on disk while the panel held an unsaved edit: the file wins, the edit was dropped",
                self.path.display()
            ));
        }
        self.gesture = None;
        self.refused = None;
        self.read_only = false;
        self.disk = now.clone();
        self.text = now;
        true
    }
}

fn read(path: &Path) -> Result<String> {
    crate::input::read_text(path, "a scene file")
}

fn readonly(path: &Path) -> bool {
    std::fs::metadata(path).is_ok_and(|m| m.permissions().readonly())
}

#[cfg(test)]
mod tests {
    use super::super::scene_text::{set, Step};
    use super::*;

    const SRC: &str = "Scene( // the scene\n    a: 1,\n    b: 2.0, // bee\n)\n";

    fn ok(_: &str) -> std::result::Result<(), String> {
        Ok(())
    }

    fn field(n: &str) -> Vec<Step> {
        vec![Step::Field(n.into())]
    }

    fn setup(name: &str) -> (PathBuf, Editor) {
        let dir = std::env::temp_dir().join(format!("voltex-editor-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("s.ron");
        std::fs::write(&path, SRC).unwrap();
        let e = Editor::open(&path).unwrap();
        (path, e)
    }

    #[test]
    fn edits_are_written_undone_and_redone() {
        let (path, mut e) = setup("undo");
        let edit = set(e.text(), &field("a"), "5").unwrap();
        assert!(e.edit(edit, false, ok));
        assert_eq!(std::fs::read_to_string(&path).unwrap(), SRC.replace("a: 1", "a: 5"));
        assert!(!e.reload(), "our own write is not a change");
        assert!(e.undo(ok));
        assert_eq!(std::fs::read_to_string(&path).unwrap(), SRC);
        assert!(e.redo(ok));
        assert_eq!(std::fs::read_to_string(&path).unwrap(), SRC.replace("a: 1", "a: 5"));
        std::fs::remove_dir_all(path.parent().unwrap()).ok();
    }

    #[test]
    fn a_drag_is_written_once_and_undone_at_once() {
        let (path, mut e) = setup("drag");
        for v in ["2.5", "3.0", "3.5"] {
            let edit = set(e.text(), &field("b"), v).unwrap();
            assert!(e.edit(edit, true, ok));
            assert_eq!(std::fs::read_to_string(&path).unwrap(), SRC, "written while dragging");
        }
        e.end_gesture();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), SRC.replace("2.0", "3.5"));
        assert!(e.undo(ok));
        assert_eq!(std::fs::read_to_string(&path).unwrap(), SRC);
        assert!(!e.undo(ok));
        std::fs::remove_dir_all(path.parent().unwrap()).ok();
    }

    #[test]
    fn a_refused_edit_leaves_the_file_and_marks_the_field() {
        let (path, mut e) = setup("refused");
        let edit = set(e.text(), &field("a"), "-3").unwrap();
        assert!(!e.edit(edit, false, |_| Err("expected a plane count in 1..=16384, found -3".into())));
        assert_eq!(e.refused.as_ref().map(|r| r.0.clone()), Some(field("a")));
        assert_eq!(std::fs::read_to_string(&path).unwrap(), SRC);
        assert_eq!(e.text(), SRC);
        std::fs::remove_dir_all(path.parent().unwrap()).ok();
    }

    #[test]
    fn the_file_wins_over_an_unsaved_edit() {
        let (path, mut e) = setup("wins");
        let edit = set(e.text(), &field("b"), "9.0").unwrap();
        assert!(e.edit(edit, true, ok));
        std::fs::write(&path, SRC.replace("a: 1", "a: 7")).unwrap();
        assert!(e.reload());
        assert_eq!(e.text(), SRC.replace("a: 1", "a: 7"));
        assert!(e.note.as_ref().unwrap().contains("the file wins"), "{:?}", e.note);
        e.end_gesture();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), SRC.replace("a: 1", "a: 7"));
        std::fs::remove_dir_all(path.parent().unwrap()).ok();
    }

    #[test]
    fn a_read_only_file_keeps_edits_in_memory() {
        let (path, mut e) = setup("readonly");
        let mut perms = std::fs::metadata(&path).unwrap().permissions();
        perms.set_readonly(true);
        std::fs::set_permissions(&path, perms.clone()).unwrap();
        let edit = set(e.text(), &field("a"), "4").unwrap();
        assert!(e.edit(edit, false, ok));
        assert!(e.read_only && e.unsaved());
        assert!(e.note.as_ref().unwrap().contains("read-only"), "{:?}", e.note);
        assert_eq!(std::fs::read_to_string(&path).unwrap(), SRC);
        assert_eq!(e.text(), SRC.replace("a: 1", "a: 4"));
        // Made writable again (the watcher sees the change of mode): the edit is written.
        #[allow(clippy::permissions_set_readonly_false)]
        perms.set_readonly(false);
        std::fs::set_permissions(&path, perms).unwrap();
        assert!(!e.reload());
        assert_eq!(std::fs::read_to_string(&path).unwrap(), SRC.replace("a: 1", "a: 4"));
        std::fs::remove_dir_all(path.parent().unwrap()).ok();
    }
}
