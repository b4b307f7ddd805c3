//! AOVs (extra images: depth, coverage, transmittance, ...): the graph declares them (`aovs`),
//! a render asks for some by name (`--aov`, a scene's `aovs`); their textures become graph
//! outputs, so the passes that write them are kept only then, and are read back as EXR channels.

use crate::error::{Error, FileLoc, Result};
use crate::graph::{AovChannels, Downsample, Format, Graph, ResourceDecl, MAX_CHANNEL_BYTES};
use crate::io::Image;

/// An AOV a render writes.
#[derive(Debug, Clone, PartialEq)]
pub struct PlannedAov {
    /// The AOV's name in the graph (`--aov NAME`).
    pub name: String,
    /// Graph textures read back, with how many of their channels (R, G, B, A in order) are used.
    pub(crate) textures: Vec<(String, usize)>,
    /// Per texture channel read (texture after texture), its EXR channel name, if written.
    pub channels: Vec<Option<String>>,
    pub(crate) downsample: Downsample,
}

/// Where a requested AOV name was written: the scene's `aovs` (located) or the command line.
pub(crate) struct Requested<'a> {
    pub(crate) names: &'a [String],
    pub(crate) at: Option<FileLoc>,
}

/// Resolves the requested AOVs against `graph`'s declarations for a scene whose objects are
/// `objects` (in order: `object.index` in WGSL), and adds their textures to the graph's outputs.
pub fn plan(graph: &mut Graph, requested: Requested, objects: &[&str]) -> Result<Vec<PlannedAov>> {
    let mut out: Vec<PlannedAov> = Vec::new();
    let err = |msg: String| match &requested.at {
        Some(at) => Error::at(at.clone(), msg),
        None => Error::Invalid(msg),
    };
    for name in requested.names {
        if out.iter().any(|a| &a.name == name) {
            continue;
        }
        let Some(decl) = graph.file.aovs.get(name) else {
            let known: Vec<&String> = graph.file.aovs.keys().collect();
            return Err(err(format!(
                "unknown AOV `{name}`: the graph {} declares {known:?}",
                graph.path.display()
            )));
        };
        let formats: Vec<Format> = decl
            .textures
            .iter()
            .map(|t| match graph.file.resources.get(t) {
                Some(ResourceDecl::Texture { format, .. }) => *format,
                _ => Format::R32Float, // checked when the graph was parsed
            })
            .collect();
        if let AovChannels::Objects(_) = &decl.channels {
            let capacity: usize = formats.iter().map(|f| decl.channels_of(*f)).sum();
            if objects.len() > capacity {
                return Err(err(format!(
                    "AOV `{name}` holds {capacity} objects (graph {}), this scene has {}",
                    graph.path.display(),
                    objects.len()
                )));
            }
        }
        let channels = decl.channel_names(&formats, objects);
        if let Some(long) = channels.iter().flatten().find(|c| c.len() > MAX_CHANNEL_BYTES) {
            return Err(err(format!(
                "AOV `{name}`: channel name `{long}` is longer than the {MAX_CHANNEL_BYTES} bytes EXR allows: shorten the object's name"
            )));
        }
        for t in &decl.textures {
            if !graph.file.outputs.contains(t) {
                graph.file.outputs.push(t.clone());
            }
        }
        let used = formats.iter().map(|f| decl.channels_of(*f));
        out.push(PlannedAov {
            name: name.clone(),
            textures: decl.textures.iter().cloned().zip(used).collect(),
            channels,
            downsample: decl.downsample,
        });
    }
    Ok(out)
}

/// The named channels of an AOV's read-back textures (rendered at `supersample` times the
/// output size), reduced to the output size.
pub(crate) fn channels(aov: &PlannedAov, images: Vec<Image>, supersample: u32) -> Vec<(String, Vec<f32>)> {
    let mut names = aov.channels.iter();
    let mut out = Vec::new();
    for (image, (_, used)) in images.into_iter().zip(&aov.textures) {
        let image = match aov.downsample {
            Downsample::Mean => image.box_downsample(supersample),
            Downsample::Min => image.min_downsample(supersample),
        };
        for c in 0..*used {
            let Some(name) = names.next() else { break };
            if let Some(name) = name {
                out.push((name.clone(), image.pixels.iter().map(|p| p[c]).collect()));
            }
        }
    }
    out
}

/// A per-object AOV needs each object drawn by its own graph instance: objects a method draws
/// together in one instance (Reference's ray caster) share one layer, so at most one may ask.
pub(crate) fn check_groups(
    aovs: &[PlannedAov],
    graph: &Graph,
    groups: &[Box<dyn crate::methods::MethodPlan>],
    objects: &[crate::methods::ObjectPlan],
) -> Result<()> {
    let per_object = aovs
        .iter()
        .find(|a| matches!(graph.file.aovs.get(&a.name).map(|d| &d.channels), Some(AovChannels::Objects(_))));
    let Some(aov) = per_object else { return Ok(()) };
    for g in groups {
        let members = g.members();
        if members.len() > 1 {
            let names: Vec<&str> = members.iter().map(|&i| objects[i].object.name.as_str()).collect();
            return Err(Error::Invalid(format!(
                "AOV `{}` is per object, but objects {names:?} are drawn together in one layer (their method casts all its objects' rays at once): ask for it with one such object at most",
                aov.name
            )));
        }
    }
    Ok(())
}
