//! The reference every configuration is measured against: a given EXR, the
//! cached render, or a new path-traced render stored in the cache.

use super::*;

/// The reference: the given EXR, the cached render, or a new render with
/// `seed` (stored in the cache); written to `path` either way.
pub(super) fn reference(
    common: &Common,
    seed: u32,
    (gpu, scene): (&Gpu, &weft_scene::Scene),
    camera: &str,
    path: &Path,
) -> Result<(LinearImage, ReferenceInfo)> {
    let Extent { width, height } = common.size;
    if let Some(given) = &common.reference_image {
        let image = LinearImage::read_exr(given)?;
        image.check_radiance(given)?;
        if (image.width, image.height) != (width, height) {
            bail!(
                "--reference-image {} is {}x{}, but --size asks for {width}x{height} (images are not resampled)",
                given.display(),
                image.width,
                image.height
            );
        }
        image.write_exr(path)?;
        return Ok((
            image,
            ReferenceInfo {
                params: BTreeMap::new(),
                graph: None,
                spp: None,
                seed: None,
                cached: false,
                image: given.clone(),
                seconds: 0.0,
                noise_floor: None,
            },
        ));
    }
    let settings = RenderSettings {
        graph: common.reference.clone(),
        extent: common.size,
        camera: Some(camera.to_string()),
        samples: Some(common.spp),
        params: common
            .reference_params
            .iter()
            .cloned()
            .chain([("seed".to_string(), ParamValue::Number(f64::from(seed)))])
            .collect(),
        cache_dir: weft_scene::cache::user_cache_dir(),
        ..RenderSettings::default()
    };
    let graph = weft_render::load_graph(&settings)?;
    // `--features` are for the configurations; the reference takes the
    // toggles it knows (`!textures`), not raster ones (`!bloom`).
    let settings = RenderSettings {
        features: graph.known_toggles(&common.features),
        extra_readback: graph.graph().readback_names(),
        ..settings
    };
    let info = |cached, image, seconds| ReferenceInfo {
        params: common
            .reference_params
            .iter()
            .map(|(k, v)| (k.clone(), param_text(v)))
            .collect(),
        graph: Some(common.reference.clone()),
        spp: Some(common.spp),
        seed: Some(seed),
        cached,
        image,
        seconds,
        noise_floor: None,
    };
    let cache = weft_scene::cache::user_cache_dir()
        .filter(|_| !common.no_cache)
        .map(|root| ReferenceCache::new(&root));
    let digest = match &cache {
        Some(_) => Some(
            reference_key((common, seed), (gpu, scene), camera, (&graph, &settings))?.digest()?,
        ),
        None => None,
    };
    // The reference the report links to is always an EXR in the output folder;
    // the cache keeps its own framed copy.
    if let (Some(cache), Some(digest)) = (&cache, &digest) {
        match cache.load(digest, width, height) {
            Ok(Some(image)) => {
                image.write_exr(path)?;
                return Ok((image, info(true, path.to_path_buf(), 0.0)));
            }
            Ok(None) => {}
            Err(damaged) => eprintln!("warning: {damaged}"),
        }
    }
    let started = std::time::Instant::now();
    let rendered = render(gpu, scene, &graph, &settings, "reference")?;
    let image = linear(first_readback(&rendered, &common.reference)?);
    let seconds = started.elapsed().as_secs_f64();
    // A cache that cannot be written (read-only, full) costs a render next
    // time, as `weft render`'s caches do: a warning, never the comparison.
    if let (Some(cache), Some(digest)) = (&cache, &digest) {
        if let Err(e) = cache.store(digest, &image) {
            eprintln!("warning: {e}; the reference is not cached (it is rendered again next time)");
        }
    }
    image.write_exr(path)?;
    Ok((image, info(false, path.to_path_buf(), seconds)))
}

/// Every input of the reference render: the scene's files, the graph's
/// files and its shaders' sources, and the settings.
fn reference_key(
    (common, seed): (&Common, u32),
    (gpu, scene): (&Gpu, &weft_scene::Scene),
    camera: &str,
    (graph, settings): (&weft_graph::Prepared, &RenderSettings),
) -> Result<ReferenceKey> {
    let mut files: BTreeSet<PathBuf> = weft_render::scene_files(scene);
    files.extend(
        graph
            .graph()
            .sources
            .iter()
            .map(|s| weft_render::normalize_path(&s.file)),
    );
    let plan = weft_render::compile_for_scene(gpu, scene, graph, settings)?;
    let mut shaders = weft_gpu::pipeline::PipelineCache::new()?;
    files.extend(weft_render::shader_files(&mut shaders, &plan)?.into_keys());
    Ok(ReferenceKey {
        files: files.into_iter().filter(|f| f.is_file()).collect(),
        camera: camera.to_string(),
        width: common.size.width,
        height: common.size.height,
        spp: common.spp,
        seed,
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
