//! ProbeSlices: a method registered by the tests alone (`#[cfg(feature = "test-method")]` in
//! `for_each_method!`), the worked example of `docs/src/architecture.md`'s "Adding a method".
//! It draws an object as view slicing does, under its own name and one knob, so it takes no
//! kernel or graph pass of its own; everything else a method has (its knobs, plug-in, sweep,
//! shard cost, panel knobs, command-line name) is its own. The tests below, compiled into the
//! library's unit tests, check that it shows up everywhere with no edit outside this folder.

/// Its scene-file knobs (`knobs.rs`, compiled in the scene layer: `scene::methods`).
pub(crate) use crate::scene::methods::probe_slices as knobs;
mod plan;
mod plugin;

/// What ProbeSlices brings to the render graph: nothing of its own (its plan draws with view
/// slicing's passes).
pub(crate) const CONTRIBUTION: crate::methods::Contribution = crate::methods::Contribution {
    method: "ProbeSlices",
    filters: &[],
    resources: &[],
    counts: &[],
    texel_resources: &[],
    gather: None,
};

#[cfg(test)]
mod tests {
    use crate::methods::plugin::{panel_knobs, MethodKind};
    use crate::scene::Method;

    fn probe() -> MethodKind {
        MethodKind::from_cli("probe-slices").expect("the command line knows the test method")
    }

    #[test]
    fn the_test_method_is_registered_everywhere() {
        let kind = probe();
        // The scene file, its text and the panel.
        let m: Method = crate::scene::options().from_str("ProbeSlices(planes: 12)").unwrap();
        assert_eq!(m.kind(), kind);
        assert_eq!(m.text(), "ProbeSlices(planes: 12)");
        let panel = panel_knobs().iter().find(|k| k.name == "ProbeSlices").expect("on the panel");
        assert_eq!(panel.chosen, Some("ProbeSlices(planes: 16)"));
        // `--method` switches to it; pareto sweeps it by default alongside the others.
        assert!(kind.switchable());
        let switched = crate::methods::options::RenderOptions { method: Some(kind), ..Default::default() };
        assert_eq!(switched.apply(&Method::Reference(Default::default())).kind(), kind);
        // The shard balance costs it by its own rate.
        assert_eq!(m.plugin().kpixel_ms(), 30.0);
        assert!(crate::methods::REGISTRY.iter().any(|c| c.method == "ProbeSlices"));
    }

    /// A scene drawn with it is costed at its own rate when the farm balances shards.
    #[test]
    fn shard_costs_use_its_rate() {
        let dir = std::env::temp_dir().join(format!("voltex-probe-shards-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let scene = std::fs::read_to_string(crate::project_root().join("scenes/view_slices/flat_box.ron")).unwrap();
        let probe = replaced(&scene, "ViewSlices(planes: 256, lighting: Baked)", "ProbeSlices(planes: 256)");
        std::fs::write(dir.join("probe.ron"), probe).unwrap();
        let entries = crate::regress::find(&dir).unwrap();
        let cost = crate::regress::shards::cost(&dir.join("out"), &entries[0], Some((100, 100)));
        assert!(!cost.measured);
        // The fixed cost plus 30 ms per 1000 pixels.
        assert!((cost.ms - (150.0 + 30.0 * 10.0)).abs() < 1e-9, "{}", cost.ms);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// `text` with every `from` replaced, checking there was one.
    fn replaced(text: &str, from: &str, to: &str) -> String {
        assert!(text.contains(from), "the scene uses {from}");
        text.replace(from, to)
    }
}
