//! A measuring session: the scene, the device and the reference, then each
//! configuration rendered and measured against it (compare and sweep).

use super::reference::reference as render_reference;
use super::*;

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
    /// The configurations' graphs, each loaded once per file and parameters.
    graphs: crate::graphs::Loaded,
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
    /// where an uncached reference is written); `graphs` are the
    /// configurations' graphs loaded so far.
    pub fn open(common: &Common, out: &Path, graphs: crate::graphs::Loaded) -> Result<Self> {
        if common.no_cache {
            weft_gpu::spirv_cache::set_dir(None);
        }
        let cache = weft_scene::cache::user_cache_dir().filter(|_| !common.no_cache);
        let scene = weft_render::load_scene(common.scene(), cache.as_deref(), None)
            .with_context(|| format!("loading {}", common.scene().display()))?;
        let camera = match &common.camera {
            Some(name) => name.clone(),
            None => match scene.cameras.first() {
                Some(c) => c.name.clone(),
                None => bail!("{} has no camera", common.scene().display()),
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
        let (reference, mut info) = render_reference(
            common,
            common.seed,
            (&gpu, &scene),
            &camera,
            &out.join("reference.exr"),
        )?;
        if common.noise_floor {
            let seed = common.seed.wrapping_add(1);
            let path = out.join(format!("reference-seed{seed}.exr"));
            let (other, _) = render_reference(common, seed, (&gpu, &scene), &camera, &path)?;
            info.noise_floor = Some(weft_compare::report::NoiseFloor {
                seed,
                flip: hdr_flip(&reference, &other).mean,
                image: path,
            });
        }
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
            graphs,
        })
    }

    /// Renders `graph` with `features` and `params`: one warm-up frame, then
    /// `common.frames` frames. Every frame shows the scene at the reference's
    /// time (0): frames repeat one scene state, so the image measured is the
    /// state the reference shows, however many frames are timed.
    fn render_configuration(
        &mut self,
        common: &Common,
        name: &str,
        graph: &Path,
        (features, params): (&[String], &[(String, ParamValue)]),
    ) -> Result<(
        Rendered,
        RenderSettings,
        std::sync::Arc<weft_graph::Prepared>,
    )> {
        let settings = RenderSettings {
            graph: graph.to_path_buf(),
            extent: common.size,
            frames: common.frames + 1,
            frame_time: 0.0,
            camera: Some(self.camera.clone()),
            features: features.to_vec(),
            params: params.iter().cloned().collect(),
            timing: match self.timer {
                Timer::Gpu => TimingMode::GpuTimestamps,
                Timer::Cpu => TimingMode::CpuPerPass,
            },
            cache_dir: weft_scene::cache::user_cache_dir(),
            ..RenderSettings::default()
        };
        let loaded = self.graphs.get(&settings)?;
        let settings = RenderSettings {
            extra_readback: loaded.graph().readback_names(),
            ..settings
        };
        let rendered = render(&self.gpu, &self.scene, &loaded, &settings, name)?;
        Ok((rendered, settings, loaded))
    }

    /// Renders `graph` and keeps only its timings (a round before the
    /// measured one).
    pub fn time(
        &mut self,
        common: &Common,
        name: &str,
        graph: &Path,
        features: &[String],
        params: &[(String, ParamValue)],
    ) -> Result<Timings> {
        let (rendered, ..) = self.render_configuration(common, name, graph, (features, params))?;
        Ok(Timings::of(&rendered))
    }

    /// Renders `graph` and measures it against the reference; its frame
    /// times are this render's with `earlier` rounds' added.
    pub fn measure(
        &mut self,
        common: &Common,
        name: &str,
        graph: &Path,
        (features, params): (&[String], &[(String, ParamValue)]),
        mut earlier: Timings,
    ) -> Result<Measured> {
        let (rendered, settings, loaded) =
            self.render_configuration(common, name, graph, (features, params))?;
        // The graph's own memory, as `weft graph plan` reports it: the images
        // read back here for measuring are kept whole only for measuring.
        let as_shipped = RenderSettings {
            extra_readback: Vec::new(),
            ..settings
        };
        let transient_bytes =
            weft_render::compile_for_scene(&self.gpu, &self.scene, &loaded, &as_shipped)?
                .memory
                .transient_bytes;
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
        // Like with like: the LDR measures see what the reference models.
        let measured_ldr = if common.post {
            output.clone()
        } else {
            super::tonemap(&image)
        };
        earlier.extend(&Timings::of(&rendered));
        let (frame_spread, passes) = earlier.summary();
        let configuration = Configuration {
            name: name.to_string(),
            graph: graph.to_path_buf(),
            features: rendered.plan.features.to_vec(),
            params: params
                .iter()
                .map(|(k, v)| (k.clone(), param_text(v)))
                .collect(),
            flip: flip.mean,
            flip_ldr: ldr_flip(&self.reference_ldr, &measured_ldr).mean,
            rmse: rmse(&image.pixels, &self.reference.pixels),
            rel_mse: rel_mse(&image.pixels, &self.reference.pixels),
            psnr: psnr(&measured_ldr, &self.reference_ldr),
            luminance_ratio: luminance_ratio(&image.pixels, &self.reference.pixels),
            frame_ms: frame_spread.median,
            frame_spread,
            passes,
            transient_bytes,
            device_bytes: rendered.report.memory.allocated_bytes,
            caveats: rendered.plan.caveats.clone(),
            views: rendered
                .views
                .iter()
                .map(|(name, v)| {
                    let numbers = ViewNumbers {
                        mean: v.mean,
                        median: v.median,
                        p95: v.p95,
                        max: v.max,
                    };
                    (name.clone(), numbers)
                })
                .collect(),
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
