//! `weft compare`: configurations (graphs) of one scene against one trusted
//! reference — a path-traced render, cached on disk, or a given EXR — with
//! image error (HDR-FLIP, LDR-FLIP, RMSE, relative MSE, PSNR) beside time
//! and memory (docs/compare.md).

use anyhow::{bail, Context, Result};
use clap::{Args, ValueEnum};
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use weft_compare::cache::{ReferenceCache, ReferenceKey};
use weft_compare::metrics::median;
use weft_compare::report::{
    write_contact_sheet, write_flip_map, Configuration, PassTime, ReferenceInfo, Report,
    SheetColumn,
};
use weft_compare::{
    hdr_flip, ldr_flip, luminance_ratio, psnr, rel_mse, rmse, LinearImage, SrgbImage,
};
use weft_gpu::{DeviceKind, Gpu, GpuOptions, Readback, TimingMode};
use weft_graph::plan::Extent;
use weft_graph::schema::ParamValue;
use weft_render::{render_with_progress, RenderSettings, Rendered};

/// How per-pass times are taken.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Timer {
    /// GPU timestamps (meaningless for compute on lavapipe).
    Gpu,
    /// CPU wall time of each pass submitted alone.
    Cpu,
}

/// What `weft compare` and `weft sweep` share: the scene, the view, the
/// reference and how configurations are measured.
#[derive(Args)]
pub struct Common {
    /// The scene file.
    pub scene: PathBuf,
    /// Feature toggles for every configuration (`name` on, `!name` off).
    #[arg(long, value_delimiter = ',')]
    pub features: Vec<String>,
    /// Camera name; the scene's first camera by default.
    #[arg(long)]
    pub camera: Option<String>,
    /// Image size, WIDTHxHEIGHT.
    #[arg(long, default_value = "640x360", value_parser = clap::value_parser!(Extent))]
    pub size: Extent,
    /// The reference graph (progressive), rendered to --spp samples.
    #[arg(
        long,
        default_value = "graphs/pathtrace.ron",
        conflicts_with = "reference_image"
    )]
    pub reference: PathBuf,
    /// Samples per pixel of the reference render.
    #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u64).range(1..))]
    pub spp: u64,
    /// The reference render's seed.
    #[arg(long, default_value_t = 0)]
    pub seed: u32,
    /// A parameter of the reference graph, NAME=VALUE (`max_depth=2` for
    /// direct light only); repeatable.
    #[arg(long = "reference-param", value_parser = crate::render_cmd::parse_param)]
    pub reference_params: Vec<(String, ParamValue)>,
    /// A linear EXR to use as the reference instead of rendering one; it must
    /// have the size asked for.
    #[arg(long)]
    pub reference_image: Option<PathBuf>,
    /// Frames measured per configuration, after one warm-up frame.
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..))]
    pub frames: u32,
    /// Per-pass timer: `gpu` timestamps, or `cpu` wall time per pass; by
    /// default `cpu` on a software device (lavapipe), `gpu` elsewhere.
    #[arg(long)]
    pub timer: Option<Timer>,
    /// Read and write no cached data: render the reference even when the
    /// cache has it (and do not store it), import every model and compile
    /// every shader again.
    #[arg(long)]
    pub no_cache: bool,
    /// Use the first device whose name contains this.
    #[arg(long)]
    pub device: Option<String>,
    /// Enable the validation layer with synchronization validation; any error or
    /// warning makes the command fail.
    #[arg(long)]
    pub validate: bool,
}

/// Arguments of `weft compare`.
#[derive(Args)]
pub struct CompareArgs {
    #[command(flatten)]
    common: Common,
    /// The configurations: graph files, comma-separated.
    #[arg(long, value_delimiter = ',', required = true)]
    graphs: Vec<PathBuf>,
    /// A parameter for every configuration, NAME=VALUE; repeatable.
    #[arg(long = "param", value_parser = crate::render_cmd::parse_param)]
    params: Vec<(String, ParamValue)>,
    /// Where the images and reports go.
    #[arg(long, default_value = "out/compare")]
    out: PathBuf,
}

/// The reference graph's exposure and the tonemap every raster graph ends
/// with (`shaders/tonemap.frag`: Reinhard per channel, then sRGB), for the
/// LDR measures of a reference that exists only as linear floats.
fn tonemap(image: &LinearImage) -> SrgbImage {
    SrgbImage {
        width: image.width,
        height: image.height,
        bytes: image
            .pixels
            .iter()
            .flat_map(|p| {
                p.map(|c| {
                    let c = if c.is_finite() { c.max(0.0) } else { 0.0 };
                    weft_compare::image_io::to_byte(weft_compare::image_io::linear_to_srgb(
                        c / (1.0 + c),
                    ))
                })
            })
            .collect(),
    }
}

/// A readback as linear RGB.
fn linear(image: &Readback) -> LinearImage {
    let rgba = image.to_rgba_f32();
    LinearImage {
        width: rgba.width(),
        height: rgba.height(),
        pixels: rgba.pixels().map(|p| [p.0[0], p.0[1], p.0[2]]).collect(),
    }
}

/// A readback as 8-bit sRGB.
fn srgb(image: &Readback) -> SrgbImage {
    let rgba = image.to_rgba8();
    SrgbImage {
        width: rgba.width(),
        height: rgba.height(),
        bytes: rgba
            .pixels()
            .flat_map(|p| [p.0[0], p.0[1], p.0[2]])
            .collect(),
    }
}

fn bar(label: &str) -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::new(0);
    bar.set_style(
        indicatif::ProgressStyle::with_template(&format!(
            "{label:>12} [{{bar:30}}] frame {{pos}}/{{len}} {{msg}} ({{elapsed}}, ETA {{eta}})"
        ))
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
        .progress_chars("=> "),
    );
    bar
}

/// Renders with a progress bar labelled `label`.
fn render(
    gpu: &Gpu,
    scene: &weft_scene::Scene,
    settings: &RenderSettings,
    label: &str,
) -> Result<Rendered> {
    let bar = bar(label);
    let rendered = render_with_progress(gpu, scene, settings, &mut |p| {
        bar.set_length(p.planned_frames.into());
        bar.set_position(p.frames.into());
        if let Some(samples) = p.samples {
            bar.set_message(format!("{samples} spp"));
        }
    })
    .with_context(|| format!("rendering {}", settings.graph.display()))?;
    bar.finish_and_clear();
    Ok(rendered)
}

/// The image a graph reads back first (its linear `hdr`).
fn first_readback<'a>(rendered: &'a Rendered, graph: &Path) -> Result<&'a Readback> {
    rendered
        .report
        .readbacks
        .first()
        .map(|(_, image)| image)
        .with_context(|| {
            format!(
                "{} reads back no linear image to compare; add `readback: [\"hdr\"]` naming its HDR image",
                graph.display()
            )
        })
}

fn param_text(value: &ParamValue) -> String {
    match value {
        ParamValue::Bool(b) => b.to_string(),
        ParamValue::Number(n) => n.to_string(),
        ParamValue::Vector(v) => v.iter().map(f64::to_string).collect::<Vec<_>>().join(","),
        ParamValue::Reference(r) => format!("${r}"),
    }
}

/// Per-pass medians over the frames after the first.
fn pass_medians(rendered: &Rendered) -> Vec<PassTime> {
    let measured = &rendered.timings[1.min(rendered.timings.len())..];
    let mut order: Vec<String> = Vec::new();
    let mut by_pass: BTreeMap<String, (Vec<f64>, String)> = BTreeMap::new();
    for frame in measured {
        for t in frame {
            if !by_pass.contains_key(&t.pass) {
                order.push(t.pass.clone());
            }
            let entry = by_pass
                .entry(t.pass.clone())
                .or_insert_with(|| (Vec::new(), t.source.label().to_string()));
            entry.0.push(t.ms);
        }
    }
    order
        .into_iter()
        .filter_map(|name| {
            let (mut ms, timer) = by_pass.remove(&name)?;
            Some(PassTime {
                name,
                ms: median(&mut ms),
                timer,
            })
        })
        .collect()
}

/// Distinct short names for the configurations: each graph's file stem,
/// numbered when two share one.
fn names(graphs: &[PathBuf]) -> Vec<String> {
    let stems: Vec<String> = graphs
        .iter()
        .map(|g| {
            g.file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_else(|| "graph".into())
        })
        .collect();
    stems
        .iter()
        .enumerate()
        .map(|(i, s)| {
            if stems.iter().filter(|o| *o == s).count() > 1 {
                format!("{s}-{}", i + 1)
            } else {
                s.clone()
            }
        })
        .collect()
}

/// The reference: the given EXR, the cached render, or a new render (stored
/// in the cache, or written to `out` with `--no-cache`).
fn reference(
    common: &Common,
    gpu: &Gpu,
    scene: &weft_scene::Scene,
    camera: &str,
    out: &Path,
) -> Result<(LinearImage, ReferenceInfo)> {
    let Extent { width, height } = common.size;
    if let Some(path) = &common.reference_image {
        let image = LinearImage::read_exr(path)?;
        image.check_radiance(path)?;
        if (image.width, image.height) != (width, height) {
            bail!(
                "--reference-image {} is {}x{}, but --size asks for {width}x{height} (images are not resampled)",
                path.display(),
                image.width,
                image.height
            );
        }
        return Ok((
            image,
            ReferenceInfo {
                params: BTreeMap::new(),
                graph: None,
                spp: None,
                seed: None,
                cached: false,
                image: path.clone(),
                seconds: 0.0,
            },
        ));
    }
    let settings = RenderSettings {
        graph: common.reference.clone(),
        extent: common.size,
        camera: Some(camera.to_string()),
        features: common.features.clone(),
        samples: Some(common.spp),
        params: common
            .reference_params
            .iter()
            .cloned()
            .chain([(
                "seed".to_string(),
                ParamValue::Number(f64::from(common.seed)),
            )])
            .collect(),
        cache_dir: weft_scene::cache::user_cache_dir(),
        extra_readback: weft_graph::load(&common.reference).readback_names(),
        ..RenderSettings::default()
    };
    let info = |cached, image, seconds| ReferenceInfo {
        params: common
            .reference_params
            .iter()
            .map(|(k, v)| (k.clone(), param_text(v)))
            .collect(),
        graph: Some(common.reference.clone()),
        spp: Some(common.spp),
        seed: Some(common.seed),
        cached,
        image,
        seconds,
    };
    let cache = weft_scene::cache::user_cache_dir()
        .filter(|_| !common.no_cache)
        .map(|root| ReferenceCache::new(&root));
    let digest = match &cache {
        Some(_) => Some(reference_key(common, gpu, scene, camera, &settings)?.digest()?),
        None => None,
    };
    // The reference the report links to is always an EXR in the output folder;
    // the cache keeps its own framed copy.
    let path = out.join("reference.exr");
    if let (Some(cache), Some(digest)) = (&cache, &digest) {
        match cache.load(digest, width, height) {
            Ok(Some(image)) => {
                image.write_exr(&path)?;
                return Ok((image, info(true, path, 0.0)));
            }
            Ok(None) => {}
            Err(damaged) => eprintln!("warning: {damaged}"),
        }
    }
    let started = std::time::Instant::now();
    let rendered = render(gpu, scene, &settings, "reference")?;
    let image = linear(first_readback(&rendered, &common.reference)?);
    let seconds = started.elapsed().as_secs_f64();
    if let (Some(cache), Some(digest)) = (&cache, &digest) {
        cache.store(digest, &image)?;
    }
    image.write_exr(&path)?;
    Ok((image, info(false, path, seconds)))
}

/// Every input of the reference render: the scene's files, the graph's
/// files and its shaders' sources, and the settings.
fn reference_key(
    common: &Common,
    gpu: &Gpu,
    scene: &weft_scene::Scene,
    camera: &str,
    settings: &RenderSettings,
) -> Result<ReferenceKey> {
    let mut files: BTreeSet<PathBuf> = weft_render::sources::scene_files(scene);
    let loaded = weft_graph::load(&common.reference);
    files.extend(
        loaded
            .sources
            .iter()
            .map(|s| weft_render::sources::normalize(&s.file)),
    );
    let plan = weft_render::compile_for_scene(gpu, scene, settings)?;
    let mut shaders = weft_gpu::pipeline::PipelineCache::new()?;
    files.extend(weft_render::sources::shader_files(&mut shaders, &plan)?.into_keys());
    Ok(ReferenceKey {
        files: files.into_iter().filter(|f| f.is_file()).collect(),
        camera: camera.to_string(),
        width: common.size.width,
        height: common.size.height,
        spp: common.spp,
        seed: common.seed,
        settings: common
            .features
            .iter()
            .cloned()
            .chain(
                common
                    .reference_params
                    .iter()
                    .map(|(k, v)| format!("{k}={}", param_text(v))),
            )
            .collect(),
    })
}

/// A loaded scene, a device and the reference, ready to measure
/// configurations against.
pub struct Session {
    gpu: Gpu,
    log: std::sync::Arc<weft_gpu::validation::ValidationLog>,
    scene: weft_scene::Scene,
    /// The camera every configuration renders.
    pub camera: String,
    /// The device's name.
    pub device: String,
    timer: Timer,
    /// The reference in linear HDR.
    pub reference: LinearImage,
    /// The reference through the engine's tonemap.
    pub reference_ldr: SrgbImage,
    /// Where it came from.
    pub info: ReferenceInfo,
}

/// One configuration's measurements, and its images for the files.
pub struct Measured {
    /// The figures.
    pub configuration: Configuration,
    /// Its linear image.
    pub image: LinearImage,
    /// Its tonemapped output.
    pub output: SrgbImage,
    /// Its HDR-FLIP error map.
    pub flip: weft_compare::FlipResult,
}

impl Session {
    /// Loads the scene, opens the device and gets the reference (`out` is
    /// where an uncached reference is written).
    pub fn open(common: &Common, out: &Path) -> Result<Self> {
        if common.no_cache {
            weft_gpu::spirv_cache::set_dir(None);
        }
        let cache = weft_scene::cache::user_cache_dir().filter(|_| !common.no_cache);
        let scene = weft_render::scene_load::load_scene(&common.scene, cache.as_deref())
            .with_context(|| format!("loading {}", common.scene.display()))?;
        let camera = match &common.camera {
            Some(name) => name.clone(),
            None => match scene.cameras.first() {
                Some(c) => c.name.clone(),
                None => bail!("{} has no camera", common.scene.display()),
            },
        };
        std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
        let gpu = Gpu::new(&GpuOptions {
            validation: common.validate,
            device: common.device.clone(),
        })?;
        let log = gpu.validation();
        let device = gpu.info().name.clone();
        let timer = common
            .timer
            .unwrap_or(if gpu.info().kind == DeviceKind::Cpu {
                Timer::Cpu
            } else {
                Timer::Gpu
            });
        let (reference, info) = reference(common, &gpu, &scene, &camera, out)?;
        let reference_ldr = tonemap(&reference);
        Ok(Self {
            gpu,
            log,
            scene,
            camera,
            device,
            timer,
            reference,
            reference_ldr,
            info,
        })
    }

    /// Renders `graph` (after one warm-up frame, `common.frames` frames) and
    /// measures it against the reference.
    pub fn measure(
        &self,
        common: &Common,
        name: &str,
        graph: &Path,
        features: &[String],
        params: &[(String, ParamValue)],
    ) -> Result<Measured> {
        let settings = RenderSettings {
            graph: graph.to_path_buf(),
            extent: common.size,
            frames: common.frames + 1,
            camera: Some(self.camera.clone()),
            features: features.to_vec(),
            params: params.iter().cloned().collect(),
            timing: match self.timer {
                Timer::Gpu => TimingMode::GpuTimestamps,
                Timer::Cpu => TimingMode::CpuPerPass,
            },
            extra_readback: weft_graph::load(graph).readback_names(),
            cache_dir: weft_scene::cache::user_cache_dir(),
            ..RenderSettings::default()
        };
        let rendered = render(&self.gpu, &self.scene, &settings, name)?;
        let image = linear(first_readback(&rendered, graph)?);
        self.reference
            .check_size(image.width, image.height, name)
            .context("configurations must render at the reference's size")?;
        let output = srgb(
            rendered
                .report
                .output
                .as_ref()
                .context("the frame produced no output image")?,
        );
        let flip = hdr_flip(&self.reference, &image);
        let mut frame_ms = rendered.frame_ms[1.min(rendered.frame_ms.len())..].to_vec();
        let configuration = Configuration {
            name: name.to_string(),
            graph: graph.to_path_buf(),
            features: rendered.plan.features.to_vec(),
            params: params
                .iter()
                .map(|(k, v)| (k.clone(), param_text(v)))
                .collect(),
            flip: flip.mean,
            flip_ldr: ldr_flip(&self.reference_ldr, &output).mean,
            rmse: rmse(&image.pixels, &self.reference.pixels),
            rel_mse: rel_mse(&image.pixels, &self.reference.pixels),
            psnr: psnr(&output, &self.reference_ldr),
            luminance_ratio: luminance_ratio(&image.pixels, &self.reference.pixels),
            frame_ms: median(&mut frame_ms),
            passes: pass_medians(&rendered),
            transient_bytes: rendered.report.transient_bytes,
            device_bytes: rendered.report.memory.allocated_bytes,
            caveats: rendered.plan.caveats.clone(),
            files: Vec::new(),
        };
        Ok(Measured {
            configuration,
            image,
            output,
            flip,
        })
    }

    /// Ends the session: prints the validation messages and says whether
    /// there were none.
    pub fn finish(self, validate: bool) -> ExitCode {
        let log = self.log.clone();
        drop(self);
        for w in weft_gpu::spirv_cache::take_warnings() {
            eprintln!("warning: {w}");
        }
        let counts = log.counts();
        for m in log.messages() {
            eprintln!("validation {:?}: {}: {}", m.severity, m.id, m.text);
        }
        if validate {
            println!("validation: {counts}");
        }
        if counts.is_clean() {
            ExitCode::SUCCESS
        } else {
            ExitCode::FAILURE
        }
    }
}

/// Runs `weft compare`.
pub fn run(args: CompareArgs) -> Result<ExitCode> {
    let common = &args.common;
    for graph in &args.graphs {
        crate::graph_cmd::check_feature_names(graph, &common.features)?;
    }
    let session = Session::open(common, &args.out)?;
    session
        .reference
        .write_exr(&args.out.join("reference.exr"))?;
    session
        .reference_ldr
        .write_png(&args.out.join("reference.png"))?;
    let mut measured = Vec::new();
    for (graph, name) in args.graphs.iter().zip(names(&args.graphs)) {
        let mut m = session.measure(common, &name, graph, &common.features, &args.params)?;
        let files = [
            args.out.join(format!("{name}.png")),
            args.out.join(format!("{name}.exr")),
            args.out.join(format!("{name}.flip.png")),
        ];
        m.output.write_png(&files[0])?;
        m.image.write_exr(&files[1])?;
        write_flip_map(&m.flip, &format!("{name} HDR-FLIP"), &files[2])?;
        m.configuration.files = files.to_vec();
        measured.push(m);
    }
    let report = Report {
        scene: common.scene.clone(),
        camera: session.camera.clone(),
        width: common.size.width,
        height: common.size.height,
        device: session.device.clone(),
        frames: common.frames,
        reference: session.info.clone(),
        configurations: measured.iter().map(|m| m.configuration.clone()).collect(),
    };
    let mut columns = vec![SheetColumn {
        label: "reference".into(),
        image: &session.reference_ldr,
        flip: None,
    }];
    columns.extend(measured.iter().map(|m| SheetColumn {
        label: m.configuration.name.clone(),
        image: &m.output,
        flip: Some(&m.flip),
    }));
    write_contact_sheet(&columns, &args.out.join("contact_sheet.png"))?;
    std::fs::write(
        args.out.join("report.json"),
        serde_json::to_string_pretty(&report)? + "\n",
    )?;
    std::fs::write(args.out.join("report.md"), report.markdown())?;
    print!("{}", report.table());
    println!("wrote {}", args.out.display());
    Ok(session.finish(common.validate))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn medians_and_names() {
        assert_eq!(median(&mut [3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&mut [4.0, 1.0, 2.0, 3.0]), 2.5);
        assert_eq!(
            names(&[
                PathBuf::from("graphs/forward.ron"),
                PathBuf::from("graphs/deferred.ron"),
                PathBuf::from("other/forward.ron"),
            ]),
            ["forward-1", "deferred", "forward-3"]
        );
    }

    #[test]
    fn the_cpu_tonemap_is_reinhard_then_srgb() {
        let image = LinearImage {
            width: 2,
            height: 1,
            pixels: vec![[0.0, 1.0, f32::INFINITY], [3.0, -1.0, f32::NAN]],
        };
        // 1 -> 0.5 -> sRGB 0.7354 -> 188; 3 -> 0.75 -> 0.8808 -> 225
        assert_eq!(tonemap(&image).bytes, [0, 188, 0, 225, 0, 0]);
    }
}
