//! JUnit XML for CI systems: one `<testcase>` per scene (class: its folder, name: its file),
//! regressed and new scenes as `<failure>`, broken scenes and references as `<error>`, and each
//! problem of the merge as an `<error>` test case of class `merge`.

use std::fmt::Write as _;
use std::path::Path;

use super::merge::Problem;
use super::record::{Found, Status};
use crate::io::atomic;
use crate::{Error, Result};

/// File name of the JUnit report beside `index.html` when `--junit` names no other file.
pub(crate) const JUNIT_FILE: &str = "junit.xml";

/// Writes the JUnit report to `path` atomically.
pub(crate) fn write(path: &Path, found: &[Found], unreadable: &[Error], problems: &[Problem]) -> Result<()> {
    atomic::write_bytes(path, xml(found, unreadable, problems).as_bytes())
}

fn xml(found: &[Found], unreadable: &[Error], problems: &[Problem]) -> String {
    let mut cases = String::new();
    let (mut failures, mut errors) = (0, 0);
    let mut seconds = 0.0;
    for f in found {
        let r = &f.record;
        let (class, name) = match r.scene.rsplit_once('/') {
            Some((dir, file)) => (dir.replace('/', "."), file),
            None => (".".to_string(), r.scene.as_str()),
        };
        seconds += r.wall_ms / 1e3;
        let _ = write!(
            cases,
            "    <testcase classname=\"{}\" name=\"{}\" time=\"{:.3}\"",
            esc(&class),
            esc(name),
            r.wall_ms / 1e3
        );
        let message = r.message.clone().unwrap_or_default();
        let kind = match r.status {
            _ if !r.failed() => None,
            Status::Regressed | Status::New => Some("failure"),
            _ => Some("error"),
        };
        match kind {
            Some(tag) => {
                if tag == "failure" {
                    failures += 1;
                } else {
                    errors += 1;
                }
                let _ = writeln!(
                    cases,
                    ">\n      <{tag} type=\"{}\" message=\"{}\">{}</{tag}>\n    </testcase>",
                    r.status.label(),
                    esc(&message),
                    esc(&metrics(r))
                );
            }
            None => {
                let _ = writeln!(
                    cases,
                    ">\n      <system-out>{}</system-out>\n    </testcase>",
                    esc(&metrics(r))
                );
            }
        }
    }
    for e in unreadable {
        errors += 1;
        let _ = writeln!(
            cases,
            "    <testcase classname=\"merge\" name=\"unreadable record\" time=\"0\">\n      \
             <error type=\"unreadable record\" message=\"{}\"/>\n    </testcase>",
            esc(&e.to_string())
        );
    }
    for p in problems {
        errors += 1;
        let _ = writeln!(
            cases,
            "    <testcase classname=\"merge\" name=\"{}\" time=\"0\">\n      <error type=\"merge\" message=\"{}\"/>\n    </testcase>",
            esc(&p.what),
            esc(&p.message)
        );
    }
    let tests = found.len() + unreadable.len() + problems.len();
    format!(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<testsuites name=\"voltex regress\" tests=\"{tests}\" \
         failures=\"{failures}\" errors=\"{errors}\" time=\"{seconds:.3}\">\n  <testsuite name=\"voltex regress\" \
         tests=\"{tests}\" failures=\"{failures}\" errors=\"{errors}\" skipped=\"0\" time=\"{seconds:.3}\">\n\
         {cases}  </testsuite>\n</testsuites>\n"
    )
}

fn metrics(r: &super::record::Record) -> String {
    let v = |x: Option<f64>| x.map(|x| format!("{x:.5}")).unwrap_or_else(|| "-".into());
    format!(
        "FLIP {} (max {}), relative RMSE {} (max {}), shard {}, {}",
        v(r.flip),
        r.max_flip,
        v(r.rel_rmse),
        r.max_rel_rmse,
        r.shard,
        r.adapter
    )
}

/// Escapes text for XML attributes and content, dropping characters XML 1.0 cannot hold.
fn esc(s: &str) -> String {
    s.chars()
        .filter(|&c| matches!(c, '\t' | '\n' | '\r') || c >= ' ')
        .map(|c| match c {
            '&' => "&amp;".to_string(),
            '<' => "&lt;".to_string(),
            '>' => "&gt;".to_string(),
            '"' => "&quot;".to_string(),
            '\n' => "&#10;".to_string(),
            c => c.to_string(),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escapes() {
        assert_eq!(esc("a<b & \"c\"\u{1}\n"), "a&lt;b &amp; &quot;c&quot;&#10;");
    }
}
