//! Graph values and kernels beyond the device's limits (issue 19): the default graph with clears
//! made NaN, inf or out of range, formats swapped, fixed sizes, targets repeated, outputs added;
//! its kernels with huge workgroup sizes and `var<private>`, `var<workgroup>` and function arrays.
//! Planned with a scene of each method (`voltex plan`), every error is at a `line:col` of the
//! graph or the kernel. The edits are also rendered and reloaded by `gpu_paths`.

use super::hostile::{example, insert_line, Tree, FLAT};
use crate::fuzz_support::check_error;
use crate::fuzz_support::runner::{accepted, fuzz, SMALL};

use proptest::prelude::*;
use proptest::sample::Index;
use voltex::render::{Blueprint, RenderOptions};
use voltex::Error;

/// One edit of the default graph or of one of its kernels (written beside it).
#[derive(Debug, Clone)]
pub(super) enum GraphEdit {
    /// The `n`-th `clear:` value replaced.
    Clear(Index, &'static str),
    Format(Index, &'static str),
    /// The `n`-th `size: Output` replaced.
    Size(Index, &'static str),
    /// The `n`-th `depth: (resource: "..."` naming another resource.
    Depth(Index, Index),
    /// The `n`-th `targets: [` list's first target repeated.
    Targets(Index, usize),
    /// Another resource added to the outputs.
    Output(Index),
    /// A kernel's first `@workgroup_size(...)` replaced.
    Workgroup(Index, [&'static str; 3]),
    /// A declaration put before line `at` of a kernel.
    Declare(Index, Index, String),
    /// A function variable put at the start of the kernel's entry point.
    Local(Index, String),
}

const CLEARS: &[&str] = &[
    "Depth(NaN)",
    "Depth(inf)",
    "Depth(-1.0)",
    "Depth(2.0)",
    "Depth(0.5)",
    "Color(NaN, 0.0, 0.0, 1.0)",
    "Color(inf, 0.0, 0.0, 1.0)",
    "Color(1e39, 0.0, 0.0, 0.0)",
    "Color(0.0, 0.0, 0.0, 0.0)",
];
const FORMATS: &[&str] = &[
    "Depth32Float",
    "Depth24Plus",
    "Rgba16Float",
    "Rgba8Unorm",
    "R32Float",
    "Rgba32Float",
    "Bgra8Unorm",
    "R32Uint",
];
const SIZES: &[&str] =
    &["Fixed(1, 1)", "Fixed(16384, 16384)", "Fixed(16385, 1)", "Fixed(0, 4)", "Fixed(8192, 8192)"];
const WORKGROUP: &[&str] =
    &["0", "1", "64", "256", "257", "1024", "65535", "65536", "4294967295", "4294967296", "-1"];
const LENGTHS: &[&str] = &["1", "4096", "4097", "16384", "100000000", "268435456", "4294967295"];

fn declaration() -> impl Strategy<Value = String> {
    let n = || prop::sample::select(LENGTHS);
    prop_oneof![
        n().prop_map(|n| format!("var<private> fuzz_p: array<vec4<f32>, {n}>;")),
        n().prop_map(|n| format!("var<workgroup> fuzz_w: array<f32, {n}>;")),
        (n(), n()).prop_map(|(n, m)| format!("var<private> fuzz_n: array<array<vec4<f32>, {n}>, {m}>;")),
        n().prop_map(|n| format!("struct FuzzS {{ a: array<f32, {n}>, }}\nvar<private> fuzz_s: FuzzS;")),
        (n(), n()).prop_map(|(n, m)| format!(
            "var<workgroup> fuzz_a: array<f32, {n}>;\nvar<workgroup> fuzz_b: array<f32, {m}>;"
        )),
    ]
}

pub(super) fn graph_edit() -> impl Strategy<Value = GraphEdit> {
    let i = any::<Index>;
    prop_oneof![
        (i(), prop::sample::select(CLEARS)).prop_map(|(n, v)| GraphEdit::Clear(n, v)),
        (i(), prop::sample::select(FORMATS)).prop_map(|(n, v)| GraphEdit::Format(n, v)),
        (i(), prop::sample::select(SIZES)).prop_map(|(n, v)| GraphEdit::Size(n, v)),
        (i(), i()).prop_map(|(n, r)| GraphEdit::Depth(n, r)),
        (i(), prop::sample::select(vec![2usize, 8, 9, 100, 100_000]))
            .prop_map(|(n, k)| GraphEdit::Targets(n, k)),
        i().prop_map(GraphEdit::Output),
        (
            i(),
            [
                prop::sample::select(WORKGROUP),
                prop::sample::select(WORKGROUP),
                prop::sample::select(WORKGROUP)
            ]
        )
            .prop_map(|(k, w)| GraphEdit::Workgroup(k, w)),
        (i(), i(), declaration()).prop_map(|(k, at, d)| GraphEdit::Declare(k, at, d)),
        (i(), prop::sample::select(LENGTHS))
            .prop_map(|(k, n)| GraphEdit::Local(k, format!("var fuzz_l: array<vec4<f32>, {n}>;"))),
    ]
}

/// Offsets of `needle` in `text`.
fn find_all(text: &str, needle: &str) -> Vec<usize> {
    text.match_indices(needle).map(|(i, _)| i).collect()
}

/// The value starting at `start`: up to the first `,` or closing bracket outside brackets.
fn value_end(text: &str, start: usize) -> usize {
    let mut depth = 0i32;
    for (i, c) in text[start..].char_indices() {
        match c {
            '(' | '[' => depth += 1,
            ')' | ']' if depth == 0 => return start + i,
            ')' | ']' => depth -= 1,
            ',' if depth == 0 => return start + i,
            _ => {}
        }
    }
    text.len()
}

/// `graph` with the value after the `n`-th `key` replaced by `value`.
fn replace_value(graph: &str, key: &str, n: &Index, value: &str) -> String {
    let at = find_all(graph, key);
    if at.is_empty() {
        return graph.to_string();
    }
    let start = at[n.index(at.len())] + key.len();
    let end = value_end(graph, start);
    format!("{}{value}{}", &graph[..start], &graph[end..])
}

/// The kernels the default graph names, in its order.
pub(super) fn graph_kernels(graph: &str) -> Vec<String> {
    let mut k: Vec<String> =
        graph.split("shader: \"").skip(1).map(|s| s[..s.find('"').unwrap()].to_string()).collect();
    k.dedup();
    k
}

/// Applies `e` to the graph text, or returns the kernel (relative path) and its new text.
pub(super) fn apply(e: &GraphEdit, graph: &mut String, tree: &Tree) -> Option<(String, String)> {
    let resources: Vec<String> = graph
        .split("        \"")
        .skip(1)
        .filter_map(|s| s.find("\": Texture").map(|i| s[..i].to_string()))
        .collect();
    let kernels = graph_kernels(graph);
    let kernel = |k: &Index| kernels[k.index(kernels.len())].clone();
    match e {
        GraphEdit::Clear(n, v) => *graph = replace_value(graph, "clear: ", n, v),
        GraphEdit::Format(n, v) => *graph = replace_value(graph, "format: ", n, v),
        GraphEdit::Size(n, v) => *graph = replace_value(graph, "size: ", n, v),
        GraphEdit::Depth(n, r) => {
            let name = format!("\"{}\"", resources[r.index(resources.len())]);
            *graph = replace_value(graph, "depth: (resource: ", n, &name);
        }
        GraphEdit::Targets(n, k) => {
            let at = find_all(graph, "targets: [");
            if let Some(&a) = at.get(n.index(at.len().max(1))) {
                let start = a + "targets: [".len();
                let end = value_end(graph, start);
                let first = graph[start..end].to_string();
                let list = vec![first; *k].join(", ");
                *graph = format!("{}{list}{}", &graph[..start], &graph[end..]);
            }
        }
        GraphEdit::Output(r) => {
            let name = &resources[r.index(resources.len())];
            *graph = graph.replacen("outputs: [", &format!("outputs: [\"{name}\", "), 1);
        }
        GraphEdit::Workgroup(k, [x, y, z]) => {
            let rel = kernel(k);
            let text = tree.text(&rel);
            let start = text.find("@workgroup_size(")?;
            let end = start + text[start..].find(')')? + 1;
            return Some((rel, format!("{}@workgroup_size({x}, {y}, {z}){}", &text[..start], &text[end..])));
        }
        GraphEdit::Declare(k, at, d) => {
            let rel = kernel(k);
            return Some((rel.clone(), insert_line(&tree.text(&rel), at, d)));
        }
        GraphEdit::Local(k, d) => {
            let rel = kernel(k);
            let text = tree.text(&rel);
            let entry = text.find("\nfn main(").or_else(|| text.find("\nfn vs_main("))?;
            let body = entry + text[entry..].find("{\n")? + 2;
            return Some((rel, format!("{}    {d}\n{}", &text[..body], &text[body..])));
        }
    }
    None
}

/// Scenes that keep different parts of the default graph (and so compile different kernels).
const GRAPH_SCENES: &[&str] = &[
    FLAT,
    "scenes/meyer_neyret/pear_grazing.ron",
    "scenes/reference/torus_egg.ron",
    "scenes/hypertextures/fig4_identity.ron",
];

#[test]
fn graph_values() {
    let tree = Tree::new("graph-values");
    let original = tree.text("frame.ron");
    let strategy = (prop::sample::select(GRAPH_SCENES), prop::collection::vec(graph_edit(), 1..4));
    fuzz("graph_values", 300, SMALL, strategy, |(scene, edits)| {
        let mut graph = original.clone();
        let mut kernel = None;
        for e in &edits {
            if let Some(k) = apply(e, &mut graph, &tree) {
                kernel = Some(k);
            }
        }
        let (path, text) = example(scene);
        let graph_path = tree.graph();
        let run = || {
            tree.with_file("frame.ron", &graph, || {
                let scene = voltex::scene::parse(&text, &path).unwrap();
                let opts = RenderOptions {
                    graph: Some(graph_path.clone()),
                    size: Some((16, 16)),
                    ..Default::default()
                };
                Blueprint::new(&scene, &opts)
                    .and_then(|bp| bp.check_limits(&voltex::gpu::budget::plan_limits(), "the plan's limit"))
            })
        };
        let result = match &kernel {
            Some((rel, k)) => tree.with_file(rel, k, run),
            None => run(),
        };
        match result {
            Ok(()) => accepted(),
            // Everything about the graph or a kernel is positioned in that file.
            Err(e) => {
                let (file, text) = match (&e, &kernel) {
                    (Error::At { loc, .. }, Some((rel, k))) if loc.path == tree.dir.join(rel) => {
                        (tree.dir.join(rel), k)
                    }
                    _ => (graph_path.clone(), &graph),
                };
                check_error(&e, &file, text, true)
            }
        }
    });
}
