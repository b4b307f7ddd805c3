//! The book (`docs/`) and README.md are kept true by these tests (no GPU needed):
//! 1. every ```ron block parses as a scene (the library's parser and checks) or a graph;
//! 2. every field and variant name of the scene types appears in the scene reference;
//! 3. every field and variant name of the graph types, and every name the runtime provides
//!    (resources, counts, object filters), appears in the graph reference;
//! 4. every relative link points at a file (and heading) that exists, and SUMMARY.md lists
//!    every chapter;
//! 5. every `voltex SUBCOMMAND` / `cargo run --release -- SUBCOMMAND` names a real subcommand,
//!    and the flags shown after it are in that subcommand's `--help`.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::process::Command;

use serde_reflection::{ContainerFormat, Format, Named, Registry, Tracer, TracerConfig, VariantFormat};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// README.md and every chapter of the book, with their text.
fn doc_files() -> Vec<(PathBuf, String)> {
    let mut files = vec![root().join("README.md")];
    let mut chapters: Vec<PathBuf> = std::fs::read_dir(root().join("docs/src"))
        .expect("docs/src exists")
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    chapters.sort();
    files.extend(chapters);
    files.into_iter().map(|p| (p.clone(), std::fs::read_to_string(&p).unwrap())).collect()
}

fn rel(p: &Path) -> String {
    p.strip_prefix(root()).unwrap_or(p).display().to_string()
}

/// A fenced code block: its language, the line of its opening fence (1-based) and its text.
struct Block {
    lang: String,
    line: usize,
    text: String,
}

fn fenced_blocks(text: &str) -> Vec<Block> {
    let mut blocks = Vec::new();
    let mut open: Option<Block> = None;
    for (i, line) in text.lines().enumerate() {
        let t = line.trim_start();
        if let Some(rest) = t.strip_prefix("```") {
            match open.take() {
                Some(b) => blocks.push(b),
                None => {
                    open = Some(Block { lang: rest.trim().to_string(), line: i + 1, text: String::new() })
                }
            }
        } else if let Some(b) = open.as_mut() {
            b.text.push_str(line);
            b.text.push('\n');
        }
    }
    assert!(open.is_none(), "an unclosed ``` fence");
    blocks
}

/// The text outside fenced blocks, each line with its number, and with inline code spans removed
/// (`prose`) or kept apart (`spans`).
struct Prose {
    /// (line, text without code spans)
    prose: Vec<(usize, String)>,
    /// (line, code span text)
    spans: Vec<(usize, String)>,
}

fn prose(text: &str) -> Prose {
    let mut out = Prose { prose: Vec::new(), spans: Vec::new() };
    let mut in_fence = false;
    // Code spans may run over a line break: join paragraphs' lines, remembering each start.
    for (i, line) in text.lines().enumerate() {
        if line.trim_start().starts_with("```") {
            in_fence = !in_fence;
            continue;
        }
        if in_fence {
            continue;
        }
        out.prose.push((i + 1, line.to_string()));
    }
    // Split each line at backticks; a span left open at the end of a line continues on the next.
    let mut kept = Vec::new();
    let mut span = String::new();
    let mut span_line = 0;
    let mut in_span = false;
    for (n, line) in &out.prose {
        let mut plain = String::new();
        for (k, part) in line.split('`').enumerate() {
            if k > 0 {
                if in_span {
                    out.spans.push((span_line, std::mem::take(&mut span)));
                } else {
                    span_line = *n;
                }
                in_span = !in_span;
            }
            if in_span {
                span.push_str(part);
            } else {
                plain.push_str(part);
            }
        }
        if in_span {
            span.push(' ');
        }
        kept.push((*n, plain));
    }
    out.prose = kept;
    out
}

/// Everything a reader sees as code on a page: inline spans and fenced blocks.
fn code_text(text: &str) -> String {
    let mut all: Vec<String> = prose(text).spans.into_iter().map(|(_, s)| s).collect();
    all.extend(fenced_blocks(text).into_iter().map(|b| b.text));
    all.join("\n")
}

fn has_word(haystack: &str, word: &str) -> bool {
    let ident = |c: char| c.is_alphanumeric() || c == '_';
    haystack.match_indices(word).any(|(i, _)| {
        let before = haystack[..i].chars().next_back();
        let after = haystack[i + word.len()..].chars().next();
        !before.is_some_and(ident) && !after.is_some_and(ident)
    })
}

// ---------------------------------------------------------------------------------------------
// 1. RON blocks

/// Folders whose assets snippets may name (a snippet parses if it parses against one of them).
const SNIPPET_FOLDERS: &[&str] = &[
    "scenes/view_slices",
    "scenes/meyer_neyret",
    "scenes/hypertextures",
    "scenes/hard_cases",
    "scenes/volumes",
    "scenes/reference",
];

/// Whether a RON text is a graph: its first value (after comments and `#![...]`) is `Graph(`.
fn is_graph(text: &str) -> bool {
    text.lines()
        .map(str::trim)
        .find(|l| !l.is_empty() && !l.starts_with("//") && !l.starts_with("#!"))
        .is_some_and(|l| l.starts_with("Graph"))
}

fn parse_ron_block(text: &str) -> Result<(), String> {
    if is_graph(text) {
        let path = root().join("graphs/docs_snippet.ron");
        return voltex::graph::Graph::parse(&path, text.to_string()).map(|_| ()).map_err(|e| e.to_string());
    }
    let mut errors = BTreeSet::new();
    for folder in SNIPPET_FOLDERS {
        match voltex::scene::parse(text, &root().join(folder).join("docs_snippet.ron")) {
            Ok(_) => return Ok(()),
            Err(e) => errors.insert(e.to_string()),
        };
    }
    Err(errors.into_iter().collect::<Vec<_>>().join("\n    or: "))
}

#[test]
fn ron_blocks_parse() {
    let mut failures = Vec::new();
    let mut count = 0;
    for (path, text) in doc_files() {
        for b in fenced_blocks(&text).into_iter().filter(|b| b.lang == "ron") {
            count += 1;
            if let Err(e) = parse_ron_block(&b.text) {
                failures.push(format!("{}:{}: ```ron block does not parse: {e}", rel(&path), b.line));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    assert!(count >= 6, "expected the book to hold at least 6 ron blocks, found {count}");
}

#[test]
fn bad_ron_blocks_fail() {
    // The check itself: a fragment, an unknown field and a bad value are refused.
    assert!(parse_ron_block("method: ViewSlices(planes: 10)").is_err());
    assert!(parse_ron_block(
        "Scene(output: (width: 8, height: 8), camera: (eye: (0, -1, 1), target: (0, 0, 0)), colour: 1)"
    )
    .is_err());
    assert!(parse_ron_block(
        "Scene(output: (width: 0, height: 8), camera: (eye: (0, -1, 1), target: (0, 0, 0)))"
    )
    .is_err());
    assert!(parse_ron_block(
        "Scene(output: (width: 8, height: 8), camera: (eye: (0, -1, 1), target: (0, 0, 0)))"
    )
    .is_ok());
    assert!(parse_ron_block("Graph(outputs: [], passes: [])").is_err());
    let blocks = fenced_blocks("a\n```ron\nx\n```\n\n```text\ny\n```\n");
    assert_eq!((blocks[0].lang.as_str(), blocks[0].line, blocks[1].line), ("ron", 2, 6));
}

// ---------------------------------------------------------------------------------------------
// 2. and 3. Names in the references

/// Field and variant names of every container in a traced registry (container names are Rust
/// type names, not file syntax, and are left out).
fn registry_names(registry: &Registry) -> BTreeSet<String> {
    fn fields(named: &[Named<Format>], out: &mut BTreeSet<String>) {
        out.extend(named.iter().map(|n| n.name.clone()));
    }
    let mut out = BTreeSet::new();
    for format in registry.values() {
        match format {
            ContainerFormat::Struct(named) => fields(named, &mut out),
            ContainerFormat::Enum(variants) => {
                for v in variants.values() {
                    out.insert(v.name.clone());
                    if let VariantFormat::Struct(named) = &v.value {
                        fields(named, &mut out);
                    }
                }
            }
            _ => {}
        }
    }
    out
}

/// Traces a Deserialize type with serde-reflection. The scene types check values while they
/// deserialize (`deserialize_with` adapters over types such as `Positive`, `SplatGrid`): the
/// tracer's default samples are chosen inside every range those checks accept (0.25 for floats:
/// positive, in [0, 1], a jitter below 0.5, an angle; 4 for integers: a resolution, a splat grid
/// of at least 4, a sphere's 3 segments), so the checks pass and every type is traced through its
/// real `Deserialize` impl, `Mark<T>`'s hand-written one included (it defers to `T`).
fn tracer() -> Tracer {
    let config = TracerConfig::default()
        .default_f32_value(0.25)
        .default_f64_value(0.25)
        .default_u32_value(4)
        .default_u64_value(4)
        .default_string_value("name".into());
    Tracer::new(config)
}

/// Traces `T` and then every enum of it again as a root: serde-reflection learns only the first
/// variant of an enum met inside another type, and tracing the enum itself walks all its
/// variants. The list of enums is checked, not trusted: `registry()` fails naming any enum whose
/// variants are still unknown (a new enum type in the files must be added here).
macro_rules! trace {
    ($root:ty; $($enum:ty),* $(,)?) => {{
        let mut t = tracer();
        t.trace_simple_type::<$root>().expect("traced");
        $(t.trace_simple_type::<$enum>().expect("traced");)*
        t.registry().expect("a complete registry: trace every enum")
    }};
}

fn scene_registry() -> Registry {
    use voltex::scene::hypertexture as h;
    use voltex::scene::*;
    trace!(Scene; Light, TexelSource, Shape, Surface, HeightScale, Method, Lighting, Compositor, Lod, Filter, Quality, Shading,
        Segments, Shadows, SliceDirections, SliceBlend, DrawOrder, h::SoftObject, h::Field, h::Operator,
        h::ShapeTransfer, h::ColorTransfer)
}

fn graph_registry() -> Registry {
    use voltex::graph::*;
    trace!(GraphFile; ResourceDecl, Format, TextureSize, Clear, BufferSize, BufferClear, Value, Instances,
        PassDecl, Dispatch, Blend, Compare, Draw, AovChannels, Downsample)
}

fn missing_in(page: &str, names: impl IntoIterator<Item = String>) -> Vec<String> {
    let text = std::fs::read_to_string(root().join("docs/src").join(page)).unwrap();
    let code = code_text(&text);
    names.into_iter().filter(|n| !has_word(&code, n)).collect()
}

#[test]
fn scene_reference_names_every_field_and_variant() {
    let names = registry_names(&scene_registry());
    // The trace reaches the nested types: a sample of names from the deepest ones.
    for n in [
        "planes",
        "draw_order",
        "Slices",
        "splat_grid",
        "Perturbed",
        "period",
        "HQ",
        "IE",
        "Metaballs",
        "wind",
    ] {
        assert!(names.contains(n), "tracing the scene types missed `{n}`: {names:?}");
    }
    let missing = missing_in("scene-reference.md", names);
    assert!(
        missing.is_empty(),
        "docs/src/scene-reference.md does not name (in code) these scene fields or variants: {missing:?}"
    );
}

/// The names the runtime provides to graphs: the renderer's own and every registered method's
/// contribution (`methods::REGISTRY`), through the vocabulary the planner checks against.
fn runtime_names() -> BTreeMap<&'static str, Vec<&'static str>> {
    let v = voltex::render::vocabulary();
    BTreeMap::from([("resource", v.resources), ("count", v.counts), ("object filter", v.filters)])
}

#[test]
fn graph_reference_names_every_field_variant_and_runtime_name() {
    let names = registry_names(&graph_registry());
    for n in ["outputs", "Texture", "Compute", "Raster", "DepthSorted", "repeat", "compare", "Fixed"] {
        assert!(names.contains(n), "tracing the graph types missed `{n}`: {names:?}");
    }
    let missing = missing_in("graph-reference.md", names);
    assert!(
        missing.is_empty(),
        "docs/src/graph-reference.md does not name these graph fields or variants: {missing:?}"
    );
    let mut runtime_missing = Vec::new();
    for (kind, list) in runtime_names() {
        assert!(!list.is_empty());
        for name in missing_in("graph-reference.md", list.iter().map(|s| s.to_string())) {
            runtime_missing.push(format!("{kind} `{name}`"));
        }
    }
    assert!(runtime_missing.is_empty(), "docs/src/graph-reference.md does not name: {runtime_missing:?}");
}

#[test]
fn name_checks_can_fail() {
    assert!(has_word("a `planes` b", "planes"));
    assert!(!has_word("plane_blocks", "planes"));
    assert!(!has_word("plane_blocks", "plane"));
    assert_eq!(code_text("x `a` y\n```\nb\n```\n`c\nd` e"), "a\nc d\nb\n");
    assert!(!missing_in("scene-reference.md", ["no_such_field_anywhere".to_string()]).is_empty());
}

// ---------------------------------------------------------------------------------------------
// 4. Links and SUMMARY.md

/// `(line, target)` of every Markdown link and image outside code.
fn links(text: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    for (n, line) in prose(text).prose {
        let mut rest = line.as_str();
        while let Some(i) = rest.find("](") {
            let after = &rest[i + 2..];
            match after.find(')') {
                Some(j) => {
                    out.push((n, after[..j].trim().to_string()));
                    rest = &after[j + 1..];
                }
                None => break,
            }
        }
    }
    out
}

/// mdBook's (and GitHub's) anchor of a heading: lowercase, spaces to `-`, other punctuation
/// dropped.
fn anchor(heading: &str) -> String {
    heading
        .trim()
        .chars()
        .filter_map(|c| match c {
            c if c.is_whitespace() => Some('-'),
            c if c.is_alphanumeric() || c == '_' || c == '-' => Some(c.to_ascii_lowercase()),
            _ => None,
        })
        .collect()
}

fn anchors(text: &str) -> BTreeSet<String> {
    let mut in_fence = false;
    let mut out = BTreeSet::new();
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            in_fence = !in_fence;
        } else if !in_fence && line.starts_with('#') {
            out.insert(anchor(line.trim_start_matches('#').replace('`', "").as_str()));
        }
    }
    out
}

#[test]
fn relative_links_resolve() {
    let mut failures = Vec::new();
    let mut count = 0;
    for (path, text) in doc_files() {
        for (line, target) in links(&text) {
            if target.contains("://") || target.starts_with("mailto:") {
                continue;
            }
            count += 1;
            let (file, frag) = match target.split_once('#') {
                Some((f, a)) => (f, Some(a)),
                None => (target.as_str(), None),
            };
            let resolved = if file.is_empty() { path.clone() } else { path.parent().unwrap().join(file) };
            if !resolved.exists() {
                failures.push(format!("{}:{line}: link to `{target}`: no such file", rel(&path)));
                continue;
            }
            if let Some(frag) = frag {
                let text = std::fs::read_to_string(&resolved).unwrap_or_default();
                if !anchors(&text).contains(frag) {
                    failures.push(format!("{}:{line}: link to `{target}`: no such heading", rel(&path)));
                }
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    assert!(count >= 20, "expected at least 20 relative links, found {count}");
}

#[test]
fn summary_lists_every_chapter() {
    let src = root().join("docs/src");
    let summary = std::fs::read_to_string(src.join("SUMMARY.md")).unwrap();
    let listed: BTreeSet<String> = links(&summary).into_iter().map(|(_, t)| t).collect();
    for (path, _) in doc_files().into_iter().skip(1) {
        let name = path.file_name().unwrap().to_str().unwrap().to_string();
        if name != "SUMMARY.md" {
            assert!(listed.contains(&name), "docs/src/SUMMARY.md does not list `{name}`");
        }
    }
    let book = std::fs::read_to_string(root().join("docs/book.toml")).unwrap();
    assert!(book.contains("[book]"), "docs/book.toml has no [book] table");
}

#[test]
fn link_checks_can_fail() {
    assert_eq!(
        links("see [a](b.md#c) and `[x](y)`, ![i](p.png)"),
        [(1, "b.md#c".into()), (1, "p.png".into())]
    );
    assert_eq!(anchor("Segments: EWA-style splatting"), "segments-ewa-style-splatting");
    assert_eq!(anchor("Ground truth: the Reference method"), "ground-truth-the-reference-method");
    assert!(anchors("# A b\n```\n# not\n```\n## `C` d").contains("c-d"));
}

// ---------------------------------------------------------------------------------------------
// 5. Commands

/// `(line, subcommand, next word, flags)` of every `voltex SUB ...` or `cargo run --release -- SUB
/// ...` in code (fenced blocks and inline spans); the next word (a bare lowercase word, if any) may
/// name a nested subcommand (`farm submit`). In fenced blocks a `#` after a space starts a comment.
fn commands(text: &str) -> Vec<(usize, String, Option<String>, Vec<String>)> {
    let mut code: Vec<(usize, String)> = prose(text).spans;
    for b in fenced_blocks(text) {
        for (k, line) in b.text.lines().enumerate() {
            let line = match line.find(" #") {
                Some(i) if b.lang != "ron" => &line[..i],
                _ => line,
            };
            code.push((b.line + 1 + k, line.to_string()));
        }
    }
    let mut out = Vec::new();
    for (n, line) in code {
        let words: Vec<&str> = line.split_whitespace().collect();
        for i in 0..words.len() {
            let sub = if words[i] == "voltex" {
                i + 1
            } else if words[i..].starts_with(&["cargo", "run", "--release", "--"]) {
                i + 4
            } else {
                continue;
            };
            let Some(name) = words.get(sub) else { continue };
            if !name.starts_with(|c: char| c.is_ascii_lowercase()) {
                continue;
            }
            let name: String = name.chars().take_while(|c| c.is_ascii_lowercase() || *c == '-').collect();
            let nested = words
                .get(sub + 1)
                .filter(|w| w.chars().all(|c| c.is_ascii_lowercase() || c == '-') && !w.starts_with('-'))
                .map(|w| w.to_string());
            let flags = words[sub + 1..]
                .iter()
                .take_while(|w| **w != "voltex" && **w != "cargo" && **w != "|" && **w != "&&")
                .filter(|w| w.starts_with("--") && w.len() > 2)
                .map(|w| {
                    w.split(['=', ',', '`', ')'])
                        .next()
                        .unwrap()
                        .trim_end_matches(['.', ':', ';'])
                        .to_string()
                })
                .collect();
            out.push((n, name, nested, flags));
        }
    }
    out
}

#[test]
fn commands_exist() {
    let exe = env!("CARGO_BIN_EXE_voltex");
    let mut help: BTreeMap<String, Option<String>> = BTreeMap::new();
    let mut failures = Vec::new();
    let mut count = 0;
    for (path, text) in doc_files() {
        for (line, sub, nested, flags) in commands(&text) {
            count += 1;
            let mut get_help = |words: Vec<&str>| {
                help.entry(words.join(" "))
                    .or_insert_with(|| {
                        let out = Command::new(exe).args(&words).arg("--help").output().expect("runs voltex");
                        out.status.success().then(|| String::from_utf8_lossy(&out.stdout).into_owned())
                    })
                    .clone()
            };
            // A nested subcommand's own help holds its flags.
            let h = match nested.as_deref().and_then(|n| get_help(vec![sub.as_str(), n])) {
                Some(h) => Some(h),
                None => get_help(vec![sub.as_str()]),
            };
            let Some(h) = h else {
                failures.push(format!("{}:{line}: `voltex {sub}` is not a subcommand", rel(&path)));
                continue;
            };
            let h = &h;
            for f in flags {
                if !has_flag(h, &f) {
                    failures.push(format!("{}:{line}: `voltex {sub}` has no flag `{f}`", rel(&path)));
                }
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    assert!(count >= 30, "expected at least 30 commands in the docs, found {count}");
    assert!(help.len() >= 9, "expected the docs to show every subcommand, found {:?}", help.keys());
}

fn has_flag(help: &str, flag: &str) -> bool {
    flag == "--help"
        || help.match_indices(flag).any(|(i, _)| {
            let after = help[i + flag.len()..].chars().next();
            !after.is_some_and(|c| c.is_alphanumeric() || c == '-')
        })
}

#[test]
fn command_checks_can_fail() {
    let found = commands("`voltex render x --size 8x8`, and\n```sh\ncargo run --release -- bake S --out o  # --not\n```\nprose voltex renders `voltex farm submit --wait`");
    assert_eq!(found.len(), 3, "{:?}", found.iter().map(|c| &c.1).collect::<Vec<_>>());
    assert_eq!((found[0].1.as_str(), found[0].3.clone()), ("render", vec!["--size".to_string()]));
    // Inline spans first, then fenced blocks.
    assert_eq!((found[1].1.as_str(), found[1].2.as_deref()), ("farm", Some("submit")));
    assert_eq!((found[2].0, found[2].1.as_str(), found[2].3.clone()), (3, "bake", vec!["--out".to_string()]));
    assert!(has_flag("  --size <SIZE>", "--size") && !has_flag("  --sizes", "--size"));
    let exe = env!("CARGO_BIN_EXE_voltex");
    assert!(!Command::new(exe).args(["no-such-command", "--help"]).output().unwrap().status.success());
}

/// Text files of the project under `dirs` (recursively) with one of `exts`.
fn text_files(dirs: &[&str], exts: &[&str]) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack: Vec<PathBuf> = dirs.iter().map(|d| root().join(d)).collect();
    while let Some(p) = stack.pop() {
        if p.is_dir() {
            stack.extend(std::fs::read_dir(&p).unwrap().map(|e| e.unwrap().path()));
        } else if p.extension().and_then(|e| e.to_str()).is_some_and(|e| exts.contains(&e)) {
            out.push(p);
        }
    }
    out
}

/// A merge resolved by hand must not leave its conflict markers in a file that still builds
/// (docs, scenes and graphs are only text to git).
#[test]
fn no_merge_conflict_markers() {
    let markers = ["<", "=", ">"].map(|c| c.repeat(7));
    let files = text_files(
        &["README.md", "Cargo.toml", "docs/src", "src", "wgsl", "graphs", "scenes", "tests", "tools", ".ci"],
        &["md", "rs", "wgsl", "ron", "toml", "py", "sh", "json"],
    );
    assert!(files.len() > 100, "{} files", files.len());
    let mut found = Vec::new();
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap_or_default();
        for (i, line) in text.lines().enumerate() {
            let opens = line.starts_with(&markers[0]) || line.starts_with(&markers[2]);
            if (opens && line.len() > 7 && line.as_bytes()[7] == b' ') || line == markers[1] {
                found.push(format!("{}:{}", rel(f), i + 1));
            }
        }
    }
    assert!(found.is_empty(), "merge conflict markers at {found:?}");
}
