//! Render-graph files (`graphs/*.ron`): resources and passes naming WGSL files. Bindings come from
//! the WGSL itself (naga reflection, by name); pass order from reads and writes; what a scene does
//! not use is pruned ([`plan`]); [`exec`] records and runs a frame.

pub mod exec;
pub(crate) mod expr;
pub mod plan;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::Deserialize;

use crate::error::{locate_literal, ron_error, Error, FileLoc, Result};

/// The contents of a graph file (`Graph(...)`): its outputs, resources, passes and AOVs.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
#[serde(rename = "Graph")]
pub struct GraphFile {
    /// Resources that leave the frame (read back or presented): graph textures, or buffers the
    /// runtime provides (e.g. `slice_vertices` in a debug graph). Passes that contribute to none
    /// of them are pruned.
    pub outputs: Vec<String>,
    #[serde(default, deserialize_with = "crate::input::unique_keys")]
    pub(crate) resources: BTreeMap<String, ResourceDecl>,
    pub(crate) passes: Vec<PassDecl>,
    /// Extra images a render may ask for by name (`--aov NAME`, a scene's `output.aovs`): their
    /// textures become outputs, so the passes that write them are kept only then, and are
    /// written beside the colour as EXR channels.
    #[serde(default, deserialize_with = "crate::input::unique_keys")]
    pub aovs: BTreeMap<String, AovDecl>,
}

/// An AOV: graph textures (R32Float or Rgba32Float) read back after the frame, and how their
/// channels are named in the EXR.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AovDecl {
    /// The graph textures read back, in order.
    pub textures: Vec<String>,
    pub(crate) channels: AovChannels,
    /// How `supersample` reduces a block of samples to a pixel.
    #[serde(default)]
    pub(crate) downsample: Downsample,
}

/// EXR channel names of an AOV's texture channels.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum AovChannels {
    /// One name per channel, in order: R of an R32Float texture, R, G, B, A of an Rgba32Float
    /// one, texture after texture; channels left unnamed are not written.
    Named(Vec<String>),
    /// The R, G and B channels of the textures in turn hold the scene's objects in order
    /// (`object.index` in WGSL): channel `PREFIX.OBJECT.Y` for each object (dots in the object's
    /// name become `_`). A scene with more objects than three per texture cannot ask for it.
    Objects(String),
}

/// How an AOV is reduced over a supersampled pixel's samples.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Downsample {
    /// The mean (coverage, transmittance).
    #[default]
    Mean,
    /// The smallest sample (a depth: the nearest hit).
    Min,
}

/// Longest EXR channel name (OpenEXR 2's long names).
pub(crate) const MAX_CHANNEL_BYTES: usize = 255;

impl AovDecl {
    /// Channels per texture of `format` this AOV reads: 1 for R32Float, 3 (objects) or 4 for
    /// Rgba32Float.
    pub(crate) fn channels_of(&self, format: Format) -> usize {
        match (format, &self.channels) {
            (Format::R32Float, _) => 1,
            (_, AovChannels::Objects(_)) => 3,
            _ => 4,
        }
    }

    /// The EXR channel name of each texture channel read, `None` where none is written, for a
    /// scene whose objects are `objects` (in order), given the graph's texture formats.
    pub(crate) fn channel_names(&self, formats: &[Format], objects: &[&str]) -> Vec<Option<String>> {
        let per: Vec<usize> = formats.iter().map(|f| self.channels_of(*f)).collect();
        let total: usize = per.iter().sum();
        match &self.channels {
            AovChannels::Named(names) => (0..total).map(|i| names.get(i).cloned()).collect(),
            AovChannels::Objects(prefix) => {
                let mut seen = std::collections::BTreeSet::new();
                (0..total)
                    .map(|i| {
                        let name = objects.get(i)?;
                        let mut n = format!("{prefix}.{}.Y", name.replace('.', "_"));
                        if !seen.insert(n.clone()) {
                            n = format!("{prefix}.{}_{i}.Y", name.replace('.', "_"));
                        }
                        Some(n)
                    })
                    .collect()
            }
        }
    }
}

/// A resource the graph owns (a value of `resources`), allocated only when a kept pass uses it.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum ResourceDecl {
    /// A texture, bound by name to WGSL texture globals and named by raster targets.
    Texture {
        /// The texel format.
        format: Format,
        /// Its size (default: the scene's output size).
        #[serde(default)]
        size: TextureSize,
        /// The value it holds when a frame first uses it (none: not cleared).
        #[serde(default)]
        clear: Option<Clear>,
    },
    /// A storage buffer of the frame (one for all instances), bound by name to WGSL
    /// `var<storage, read>` or `var<storage, read_write>` globals.
    Buffer {
        /// The buffer's size.
        size: BufferSize,
        /// `Zero`: zeroed every frame before the first pass that uses it; otherwise contents
        /// carry over from frame to frame (zero at first).
        #[serde(default)]
        clear: Option<BufferClear>,
    },
    /// A small uniform value set in the graph, bound by name to a WGSL `var<uniform>` of the same
    /// type.
    Parameter(Value),
}

/// The size of a graph buffer. Counts are size expressions: integer literals and the frame's
/// counts (`width`, `height`) joined by `*` and `+`, e.g. `"width * height"` (see `expr`).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum BufferSize {
    /// A size in bytes.
    Bytes(Count),
    /// A size in 4-byte words (`u32`, `f32`, `atomic<u32>`).
    Words(Count),
    /// `count` elements of `stride` bytes each.
    Elements {
        /// Element count (a size expression).
        count: Count,
        /// Bytes per element.
        stride: u32,
    },
}

impl BufferSize {
    /// The expression and the bytes per unit it counts.
    pub(crate) fn expr(&self) -> (&str, u64) {
        match self {
            BufferSize::Bytes(c) => (c, 1),
            BufferSize::Words(c) => (c, 4),
            BufferSize::Elements { count, stride } => (count, *stride as u64),
        }
    }
}

/// How a graph buffer is cleared each frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum BufferClear {
    /// Zeroed before the first pass that uses it.
    Zero,
}

/// The value of a `Parameter`, with its WGSL type.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Value {
    /// `f32`
    F32(f32),
    /// `u32`
    U32(u32),
    /// `i32`
    I32(i32),
    /// `vec4<f32>`
    Vec4(f32, f32, f32, f32),
}

impl Value {
    /// The WGSL type a `var<uniform>` bound to this value must have.
    pub(crate) fn wgsl_type(&self) -> &'static str {
        match self {
            Value::F32(_) => "f32",
            Value::U32(_) => "u32",
            Value::I32(_) => "i32",
            Value::Vec4(..) => "vec4<f32>",
        }
    }
    /// The value's bytes as WGSL lays them out.
    pub(crate) fn bytes(&self) -> Vec<u8> {
        match *self {
            Value::F32(v) => v.to_le_bytes().to_vec(),
            Value::U32(v) => v.to_le_bytes().to_vec(),
            Value::I32(v) => v.to_le_bytes().to_vec(),
            Value::Vec4(x, y, z, w) => [x, y, z, w].iter().flat_map(|v| v.to_le_bytes()).collect(),
        }
    }
}

/// The names the runtime offers a graph beyond its own resources: the object filters passes
/// are instanced over, the counts dispatches and draws use, and the resources kernels bind, as
/// the methods and the renderer declare them. The graph core checks names against it and names
/// no method itself.
#[derive(Debug, Clone, Default)]
pub struct Vocabulary {
    /// The filters passes may be instanced over (`Objects("ViewSlices")`, ...).
    pub filters: Vec<&'static str>,
    /// The count names dispatches, draws and sizes may use (`prisms`, `planes`, ...).
    pub counts: Vec<&'static str>,
    /// The resources the runtime provides, bound by name like the graph's own.
    pub resources: Vec<&'static str>,
}

/// The format of a graph texture.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Format {
    /// 8-bit RGBA, normalised (4 bytes a pixel).
    Rgba8Unorm,
    /// 16-bit float RGBA (8 bytes a pixel).
    Rgba16Float,
    /// 32-bit float RGBA (16 bytes a pixel).
    Rgba32Float,
    /// One 32-bit float channel (4 bytes a pixel).
    R32Float,
    /// 32-bit float depth (4 bytes a pixel).
    Depth32Float,
}

impl Format {
    pub(crate) fn wgpu(self) -> wgpu::TextureFormat {
        match self {
            Format::Rgba8Unorm => wgpu::TextureFormat::Rgba8Unorm,
            Format::Rgba16Float => wgpu::TextureFormat::Rgba16Float,
            Format::Rgba32Float => wgpu::TextureFormat::Rgba32Float,
            Format::R32Float => wgpu::TextureFormat::R32Float,
            Format::Depth32Float => wgpu::TextureFormat::Depth32Float,
        }
    }
    pub(crate) fn bytes_per_pixel(self) -> u64 {
        match self {
            Format::Rgba8Unorm | Format::R32Float | Format::Depth32Float => 4,
            Format::Rgba16Float => 8,
            Format::Rgba32Float => 16,
        }
    }
}

/// The size of a graph texture.
#[derive(Debug, Clone, Copy, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum TextureSize {
    /// The scene's output size.
    #[default]
    Output,
    /// A fixed `(width, height)` in pixels, each 1..=16384.
    Fixed(#[serde(deserialize_with = "side")] u32, #[serde(deserialize_with = "side")] u32),
}

/// Most colour targets of one raster pass (WebGPU's `maxColorAttachments`).
pub(crate) const MAX_TARGETS: usize = 8;

// Value checks run while deserializing, so ron positions the error at the value.
fn side<'de, D: serde::Deserializer<'de>>(d: D) -> Result<u32, D::Error> {
    let v = u32::deserialize(d)?;
    match v {
        1..=16384 => Ok(v),
        _ => Err(serde::de::Error::custom(format!("expected a texture side in 1..=16384, found {v}"))),
    }
}

fn finite<'de, D: serde::Deserializer<'de>>(d: D) -> Result<f32, D::Error> {
    let v = f32::deserialize(d)?;
    match v.is_finite() {
        true => Ok(v),
        false => Err(serde::de::Error::custom(format!("expected a finite clear value, found {v}"))),
    }
}

fn depth<'de, D: serde::Deserializer<'de>>(d: D) -> Result<f32, D::Error> {
    let v = f32::deserialize(d)?;
    match (0.0..=1.0).contains(&v) {
        true => Ok(v),
        false => Err(serde::de::Error::custom(format!("expected a depth clear value in [0, 1], found {v}"))),
    }
}

/// The value a graph texture holds when a frame first uses it.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Clear {
    /// Linear RGBA.
    Color(
        #[serde(deserialize_with = "finite")] f32,
        #[serde(deserialize_with = "finite")] f32,
        #[serde(deserialize_with = "finite")] f32,
        #[serde(deserialize_with = "finite")] f32,
    ),
    /// A depth in [0, 1], for `Depth32Float` textures.
    Depth(#[serde(deserialize_with = "depth")] f32),
}

/// Which instances a pass runs for.
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Instances {
    /// Once per frame.
    #[default]
    Frame,
    /// Once per scene object matching the filter (see [`Vocabulary::filters`]), back to front.
    Objects(String),
}

/// A pass of the graph: a compute dispatch or a raster draw naming one WGSL file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum PassDecl {
    /// A compute dispatch of one kernel.
    Compute {
        /// Unique among the graph's passes; names the pass in errors and timings.
        name: String,
        /// The WGSL file, looked up beside the graph first, then in the project.
        shader: String,
        /// The kernel's entry point (default `main`).
        #[serde(default = "default_compute_entry")]
        entry: String,
        /// Once per frame (default) or per matching object.
        #[serde(default)]
        instances: Instances,
        /// Buffers zeroed before the pass (per instance).
        #[serde(default)]
        clear: Vec<String>,
        /// How many invocations or workgroups to dispatch.
        dispatch: Dispatch,
        /// Dispatches per frame (a count name or number): kernels that resume their work from a
        /// state buffer, so no single dispatch runs long (watchdogs, software loop limits).
        #[serde(default = "one")]
        repeat: String,
    },
    /// A raster draw into colour and depth targets.
    Raster {
        /// Unique among the graph's passes; names the pass in errors and timings.
        name: String,
        /// The WGSL file, looked up beside the graph first, then in the project.
        shader: String,
        /// The vertex entry point (default `vs_main`).
        #[serde(default = "default_vertex_entry")]
        vertex: String,
        /// The fragment entry point (default `fs_main`).
        #[serde(default = "default_fragment_entry")]
        fragment: String,
        /// Once per frame (default) or per matching object.
        #[serde(default)]
        instances: Instances,
        /// Colour targets, at most 8, each a graph texture with a blend mode.
        targets: Vec<Target>,
        /// The depth target, tested (and written when asked) by the draw.
        #[serde(default)]
        depth: Option<DepthTarget>,
        /// What to draw.
        draw: Draw,
    },
}

fn one() -> String {
    "1".into()
}

fn default_compute_entry() -> String {
    "main".into()
}
fn default_vertex_entry() -> String {
    "vs_main".into()
}
fn default_fragment_entry() -> String {
    "fs_main".into()
}

impl PassDecl {
    /// The pass's name.
    pub fn name(&self) -> &str {
        match self {
            PassDecl::Compute { name, .. } | PassDecl::Raster { name, .. } => name,
        }
    }
    pub(crate) fn shader(&self) -> &str {
        match self {
            PassDecl::Compute { shader, .. } | PassDecl::Raster { shader, .. } => shader,
        }
    }
    pub(crate) fn instances(&self) -> &Instances {
        match self {
            PassDecl::Compute { instances, .. } | PassDecl::Raster { instances, .. } => instances,
        }
    }
    pub(crate) fn entry_points(&self) -> Vec<&str> {
        match self {
            PassDecl::Compute { entry, .. } => vec![entry],
            PassDecl::Raster { vertex, fragment, .. } => vec![vertex, fragment],
        }
    }
}

/// A count: a number, or a name the runtime (`width`, `height`) or a method's contribution
/// provides (`prisms`, `planes`, ...: `render::vocabulary().counts`, listed in the graph reference).
pub(crate) type Count = String;

/// How much a compute pass dispatches: invocations or workgroups per axis.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Dispatch {
    /// Invocation counts per axis; workgroup counts follow from the kernel's workgroup size.
    Threads(Count, Count, Count),
    /// Workgroup counts per axis.
    Groups(Count, Count, Count),
}

/// A colour target of a raster pass: `(resource, blend)`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Target {
    pub(crate) resource: String,
    #[serde(default)]
    pub(crate) blend: Blend,
}

/// How a raster pass writes its colour target.
#[derive(Debug, Clone, Copy, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Blend {
    /// Overwrite (the default).
    #[default]
    Replace,
    /// `src + dst * (1 - src.a)` on premultiplied colours: back-to-front compositing.
    PremultipliedOver,
    /// `src + dst`: counting and accumulation (debug views).
    Add,
}

/// The depth target of a raster pass: `(resource, write, compare)`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DepthTarget {
    pub(crate) resource: String,
    pub(crate) write: bool,
    #[serde(default)]
    pub(crate) compare: Compare,
}

/// The depth test of a raster pass.
#[derive(Debug, Clone, Copy, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Compare {
    /// Pass when nearer (the default).
    #[default]
    Less,
    /// Pass when nearer or equal.
    LessEqual,
    /// Always pass.
    Always,
}

impl Compare {
    pub(crate) fn wgpu(self) -> wgpu::CompareFunction {
        match self {
            Compare::Less => wgpu::CompareFunction::Less,
            Compare::LessEqual => wgpu::CompareFunction::LessEqual,
            Compare::Always => wgpu::CompareFunction::Always,
        }
    }
}

/// What a raster pass draws.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Draw {
    /// A vertex count (a count name or number), one instance.
    Vertices(Count),
    /// Indirect draw from a buffer holding `DrawIndirect` arguments.
    Indirect(String),
    /// Slices of several instances composited back to front: an instance whose planes' depth
    /// range overlaps no other's is drawn whole (`whole`, one `DrawIndirect`); the planes of
    /// overlapping instances are drawn one by one (`per_plane`, one `DrawIndirect` per plane),
    /// interleaved by depth.
    DepthSorted {
        /// Buffer of `DrawIndirect` arguments for instances drawn whole.
        whole: String,
        /// Buffer of `DrawIndirect` arguments, one per plane, for overlapping instances.
        per_plane: String,
    },
}

/// A parsed graph file with its source, so later checks can point at `file:line:col`.
#[derive(Debug, Clone)]
pub struct Graph {
    pub(crate) path: PathBuf,
    pub(crate) source: String,
    /// The parsed file.
    pub file: GraphFile,
}

impl Graph {
    /// Reads and parses the graph file at `path` (see [`Graph::parse`]).
    pub fn load(path: &Path) -> Result<Self> {
        let source = crate::input::read_text(path, "a graph file")?;
        Self::parse(path, source)
    }

    /// Parses `source` as the graph file `path`, checking its names; errors are at `file:line:col`.
    pub fn parse(path: &Path, source: String) -> Result<Self> {
        let file: GraphFile = ron::Options::default()
            .with_default_extension(ron::extensions::Extensions::IMPLICIT_SOME)
            .from_str(&source)
            .map_err(|e| ron_error(path, &e))?;
        let graph = Self { path: path.to_path_buf(), source, file };
        graph.check_names()?;
        Ok(graph)
    }

    /// An error at the first occurrence of the string literal `text` (or the file start).
    pub(crate) fn error_at(&self, text: &str, message: impl Into<String>) -> Error {
        let (line, col) = locate_literal(&self.source, text, 0).unwrap_or((1, 1));
        Error::at(FileLoc::new(&self.path, line, col), message)
    }

    /// An error at output `name` in the graph's `outputs` list.
    pub(crate) fn error_at_output(&self, name: &str, message: impl Into<String>) -> Error {
        let from = self.source.find("outputs").unwrap_or(0);
        let (line, col) = locate_literal(&self.source, name, from).unwrap_or((1, 1));
        Error::at(FileLoc::new(&self.path, line, col), message)
    }

    /// An error at the string literal `text` inside pass `pass`, after its field `field`.
    pub(crate) fn error_in_pass(
        &self,
        pass: &str,
        field: &str,
        text: &str,
        message: impl Into<String>,
    ) -> Error {
        let mut from = self.source.find(&format!("\"{pass}\"")).unwrap_or(0);
        from += self.source[from..].find(&format!("{field}:")).unwrap_or(0);
        let (line, col) = locate_literal(&self.source, text, from).unwrap_or((1, 1));
        Error::at(FileLoc::new(&self.path, line, col), message)
    }

    /// Byte offset of the key of resource `name` in `resources` (`"name":`), or of its first
    /// mention.
    pub(crate) fn resource_offset(&self, name: &str) -> usize {
        let needle = format!("\"{name}\"");
        let mut from = 0;
        while let Some(i) = self.source[from..].find(&needle) {
            let at = from + i;
            if self.source[at + needle.len()..].trim_start().starts_with(':') {
                return at;
            }
            from = at + needle.len();
        }
        self.source.find(&needle).unwrap_or(0)
    }

    /// An error at the declaration of resource `name`.
    pub(crate) fn error_at_resource(&self, name: &str, message: impl Into<String>) -> Error {
        let (line, col) = crate::error::line_col(&self.source, self.resource_offset(name));
        Error::at(FileLoc::new(&self.path, line, col), message)
    }

    /// An error at byte `offset` inside the string literal `text` that follows the declaration
    /// of resource `name` (a size expression).
    pub(crate) fn error_in_literal(
        &self,
        name: &str,
        text: &str,
        offset: usize,
        message: impl Into<String>,
    ) -> Error {
        let from = self.resource_offset(name);
        let needle = format!("\"{text}\"");
        let at = match self.source[from..].find(&needle) {
            Some(i) => from + i + 1 + offset,
            None => from,
        };
        let (line, col) = crate::error::line_col(&self.source, at);
        Error::at(FileLoc::new(&self.path, line, col), message)
    }

    fn check_names(&self) -> Result<()> {
        let f = &self.file;
        let mut seen = Vec::new();
        for p in &f.passes {
            if seen.contains(&p.name()) {
                return Err(self.error_at(p.name(), format!("pass `{}` is declared twice", p.name())));
            }
            seen.push(p.name());
            if let PassDecl::Raster { targets, depth, .. } = p {
                if targets.len() > MAX_TARGETS {
                    let msg = format!(
                        "pass `{}` has {} colour targets: at most {MAX_TARGETS} are allowed",
                        p.name(),
                        targets.len()
                    );
                    return Err(self.error_at(p.name(), msg));
                }
                // wgpu refuses a texture attached twice only when the frame is recorded.
                let twice =
                    |(k, t): &(usize, &Target)| targets[..*k].iter().any(|o| o.resource == t.resource);
                if let Some((_, t)) = targets.iter().enumerate().find(twice) {
                    let msg = format!("pass `{}`: target `{}` is attached twice", p.name(), t.resource);
                    return Err(self.error_in_pass(p.name(), "targets", &t.resource, msg));
                }
                let colour = targets.iter().map(|t| (&t.resource, false));
                for (t, is_depth) in colour.chain(depth.iter().map(|d| (&d.resource, true))) {
                    let Some(ResourceDecl::Texture { format, .. }) = f.resources.get(t) else {
                        return Err(self.error_at(
                            t,
                            format!("render target `{t}` is not a texture declared in `resources`"),
                        ));
                    };
                    // wgpu rejects these only when the pipeline is made; here they have a position.
                    if is_depth != (*format == Format::Depth32Float) {
                        let want = if is_depth { "a depth format (Depth32Float)" } else { "a colour format" };
                        let role = if is_depth { "depth target" } else { "colour target" };
                        return Err(self.error_in_pass(
                            p.name(),
                            if is_depth { "depth" } else { "targets" },
                            t,
                            format!("pass `{}`: {role} `{t}` needs {want}, found {format:?}", p.name()),
                        ));
                    }
                }
            }
        }
        for (name, decl) in &f.resources {
            if let ResourceDecl::Texture { format, clear: Some(clear), .. } = decl {
                let is_depth = *format == Format::Depth32Float;
                if is_depth != matches!(clear, Clear::Depth(_)) {
                    let want = if is_depth { "`Depth(..)`" } else { "`Color(..)`" };
                    let msg = format!("texture `{name}` is {format:?}: its clear must be {want}");
                    return Err(self.error_at_resource(name, msg));
                }
            }
            if let ResourceDecl::Buffer { size, .. } = decl {
                let (text, unit) = size.expr();
                expr::Expr::parse(text).map_err(|e| {
                    self.error_in_literal(name, text, e.offset, format!("buffer `{name}`: {}", e.message))
                })?;
                if unit == 0 {
                    return Err(self.error_at_resource(name, format!("buffer `{name}`: a stride of 0 bytes")));
                }
            }
        }
        self.check_aovs()?;
        if f.outputs.is_empty() {
            return Err(Error::at(FileLoc::new(&self.path, 1, 1), "expected at least one name in `outputs`"));
        }
        Ok(())
    }

    /// AOV textures must be R32Float or Rgba32Float graph textures; named channels valid EXR
    /// channel names (1 to 255 Latin-1 bytes, no NUL), not the colour's R, G, B, A, and each
    /// written once.
    fn check_aovs(&self) -> Result<()> {
        let mut seen: Vec<&str> = vec!["R", "G", "B", "A"];
        for (aov, decl) in &self.file.aovs {
            if decl.textures.is_empty() {
                return Err(self.error_in_aov(aov, aov, format!("AOV `{aov}` names no texture")));
            }
            let mut capacity = 0;
            for t in &decl.textures {
                match self.file.resources.get(t) {
                    Some(ResourceDecl::Texture { format: format @ (Format::R32Float | Format::Rgba32Float), .. }) => {
                        capacity += decl.channels_of(*format);
                    }
                    _ => {
                        return Err(self.error_in_aov(
                            aov,
                            t,
                            format!("AOV `{aov}`: `{t}` must be an R32Float or Rgba32Float texture declared in `resources`"),
                        ))
                    }
                }
            }
            let names = match &decl.channels {
                AovChannels::Named(names) => names.iter().map(String::as_str).collect(),
                AovChannels::Objects(prefix) => vec![prefix.as_str()],
            };
            if let AovChannels::Named(names) = &decl.channels {
                if names.len() > capacity {
                    return Err(self.error_in_aov(
                        aov,
                        aov,
                        format!("AOV `{aov}` names {} channels; its textures hold {capacity}", names.len()),
                    ));
                }
            }
            for n in names {
                let bad = n.is_empty()
                    || n.len() > MAX_CHANNEL_BYTES
                    || n.chars().any(|c| c as u32 > 0xff || c == '\0');
                if bad {
                    return Err(self.error_in_aov(
                        aov,
                        n,
                        format!("AOV `{aov}`: `{n}` is no EXR channel name (1 to {MAX_CHANNEL_BYTES} Latin-1 bytes without NUL)"),
                    ));
                }
                if matches!(decl.channels, AovChannels::Named(_)) {
                    if seen.contains(&n) {
                        return Err(self.error_in_aov(
                            aov,
                            n,
                            format!("AOV `{aov}`: channel `{n}` is written by the colour or another AOV"),
                        ));
                    }
                    seen.push(n);
                }
            }
        }
        Ok(())
    }

    /// An error at the string literal `text` inside AOV `aov`'s declaration.
    fn error_in_aov(&self, aov: &str, text: &str, message: impl Into<String>) -> Error {
        // The `aovs:` field: the first line that begins with it.
        let mut from = 0;
        for line in self.source.split_inclusive('\n') {
            if line.trim_start().starts_with("aovs:") {
                break;
            }
            from += line.len();
        }
        let from = from + self.source.get(from..).and_then(|s| s.find(&format!("\"{aov}\""))).unwrap_or(0);
        let (line, col) = locate_literal(&self.source, text, from).unwrap_or((1, 1));
        Error::at(FileLoc::new(&self.path, line, col), message)
    }
}
