//! The functions a script calls: objects added at load, lights, placements,
//! colours and cameras changed per frame, bounds, random numbers.

use super::*;

/// A number from a script value (integers and floats alike).
pub(super) fn number(value: &Dynamic) -> Option<f64> {
    value
        .as_float()
        .ok()
        .or_else(|| value.as_int().ok().map(|i| i as FLOAT))
}

/// One property line of an object block, from a script map entry.
pub(super) fn property(name: &str, value: &Dynamic) -> Result<String, String> {
    if let Some(n) = number(value) {
        return Ok(format!("\t{name} {n:?}\n"));
    }
    if let Some(array) = value.read_lock::<Array>() {
        let numbers: Option<Vec<String>> = array
            .iter()
            .map(|v| number(v).map(|n| format!("{n:?}")))
            .collect();
        return numbers
            .map(|n| format!("\t{name} {}\n", n.join(" ")))
            .ok_or_else(|| format!("property '{name}' must be a number or an array of numbers"));
    }
    if let Ok(text) = value.clone().into_immutable_string() {
        if text.contains('"') || text.contains('\n') {
            return Err(format!(
                "property '{name}' may not contain quotes or line breaks"
            ));
        }
        return Ok(format!("\t{name} \"{text}\"\n"));
    }
    if let Ok(flag) = value.as_bool() {
        return Ok(format!("\t{name} {}\n", u8::from(flag)));
    }
    Err(format!(
        "property '{name}' is a {}; expected a number, an array of numbers or a string",
        value.type_name()
    ))
}

/// The object block for `kind` (with an optional label) from a script map.
pub(super) fn block_text(kind: &str, label: Option<&str>, props: &Map) -> Result<String, String> {
    let mut text = match label {
        Some(l) if l.contains('"') => return Err("a name may not contain quotes".into()),
        Some(l) => format!("{kind} \"{l}\"\n{{\n"),
        None => format!("{kind}\n{{\n"),
    };
    for (name, value) in props {
        text.push_str(&property(name, value)?);
    }
    text.push_str("}\n");
    Ok(text)
}

/// Adds one object through the `.scene` reader; returns the new object's
/// index over every object of its kind in the scene, for lights and models.
pub(super) fn add_object(
    ctx: &NativeCallContext,
    state: &Shared,
    kind: &str,
    label: Option<&str>,
    props: &Map,
) -> Result<INT, Box<EvalAltResult>> {
    let mut s = lock(state);
    if !s.loading {
        return Err(fail(
            ctx,
            format!("{kind} objects are added while the scene loads, not in init or update"),
        ));
    }
    if s.objects_added >= s.object_limit {
        return Err(fail(
            ctx,
            format!(
                "{kind}: a script may add at most {} objects (lights, models and cameras) while the scene loads",
                s.object_limit
            ),
        ));
    }
    s.objects_added += 1;
    let text = block_text(kind, label, props).map_err(|m| fail(ctx, m))?;
    let scene = s.scene.clone();
    let State { desc, diag, .. } = &mut *s;
    blocks_into(&text, &scene, desc, diag)
        .map_err(|e| fail(ctx, format!("{kind}: {}", e.message())))?;
    let count = match kind {
        "model" => s.models_before.len() + s.desc.models.len(),
        _ => s.lights_before + s.desc.lights.len(),
    };
    Ok(count as INT - 1)
}

/// The object of `kind` that `props` describe, read by the `.scene` reader
/// (so a per-frame pose means what the same block in a file means), from
/// the properties in `allowed` only.
pub(super) fn read_object(
    ctx: &NativeCallContext,
    s: &State,
    function: &str,
    (kind, label): (&str, Option<&str>),
    props: &Map,
    allowed: &[&str],
) -> Result<SceneDesc, Box<EvalAltResult>> {
    if let Some(key) = props.keys().find(|k| !allowed.contains(&k.as_str())) {
        return Err(fail(
            ctx,
            format!("{function} takes {}; not '{key}'", allowed.join(", ")),
        ));
    }
    let text = block_text(kind, label, props).map_err(|m| fail(ctx, m))?;
    let mut desc = SceneDesc {
        origin: s.desc.origin,
        ..SceneDesc::default()
    };
    blocks_into(&text, &s.scene, &mut desc, &mut Diagnostics::default())
        .map_err(|e| fail(ctx, format!("{function}: {}", e.message())))?;
    Ok(desc)
}

/// A script value's numbers (one number, or an array of numbers), for the
/// property `name`.
pub(super) fn numbers_of(name: &str, value: &Dynamic) -> Result<Vec<f32>, String> {
    let wrong = || format!("'{name}' must be a number or an array of numbers");
    if let Some(n) = number(value) {
        return Ok(vec![n as f32]);
    }
    let array = value.read_lock::<Array>().ok_or_else(wrong)?;
    array
        .iter()
        .map(|v| number(v).map(|n| n as f32).ok_or_else(wrong))
        .collect()
}

/// The model-to-world transform (relative to `origin`) of a `model` block
/// with these `position`, `orientation` and `scale`, built as the `.scene`
/// reader builds it (the same rotation and scale rules) without going
/// through its text: `set_model_transform` runs per placement per step.
pub(super) fn placement_transform(props: &Map, origin: DVec3) -> Result<Mat4, String> {
    let mut position = -origin;
    let mut rotation = glam::Quat::IDENTITY;
    let mut scale = Vec3::ONE;
    for (name, value) in props {
        match name.as_str() {
            "position" => {
                let p: Vec<f64> = match value.read_lock::<Array>() {
                    Some(a) => a.iter().filter_map(number).collect(),
                    None => Vec::new(),
                };
                let [x, y, z] = p[..] else {
                    return Err(format!(
                        "'position' expects an array of 3 numbers, found {value}"
                    ));
                };
                position = DVec3::new(x, y, z) - origin;
            }
            "orientation" => {
                rotation = crate::desc::rotation_from("orientation", &numbers_of(name, value)?)?
            }
            "scale" => scale = crate::desc::scale_from(&numbers_of(name, value)?)?,
            other => {
                return Err(format!(
                    "'{other}' is not a transform property (position, orientation, scale)"
                ))
            }
        }
    }
    Ok(Mat4::from_scale_rotation_translation(
        scale,
        rotation,
        position.as_vec3(),
    ))
}

/// The index of the `what` that `index` refers to (of `count`), for the
/// per-frame functions.
pub(super) fn frame_index(
    ctx: &NativeCallContext,
    s: &State,
    (what, count): (&str, usize),
    index: INT,
) -> Result<usize, Box<EvalAltResult>> {
    if s.loading {
        return Err(fail(
            ctx,
            format!("{what}s are changed in init or update, after the scene has loaded"),
        ));
    }
    usize::try_from(index)
        .ok()
        .filter(|&i| i < count)
        .ok_or_else(|| fail(ctx, format!("no {what} {index}: the scene has {count}")))
}

/// The light `index` refers to, for the per-frame functions.
pub(super) fn light_index(
    ctx: &NativeCallContext,
    s: &State,
    index: INT,
) -> Result<usize, Box<EvalAltResult>> {
    frame_index(ctx, s, ("light", s.lights.len()), index)
}

/// `v` as a script array of three floats.
pub(super) fn array3(v: DVec3) -> Array {
    vec![v.x.into(), v.y.into(), v.z.into()]
}

/// Three numbers (integers or floats) as a finite vector.
pub(super) fn vec3(
    ctx: &NativeCallContext,
    x: &Dynamic,
    y: &Dynamic,
    z: &Dynamic,
) -> Result<DVec3, Box<EvalAltResult>> {
    let (Some(x), Some(y), Some(z)) = (number(x), number(y), number(z)) else {
        return Err(fail(ctx, "expected three numbers"));
    };
    let v = DVec3::new(x, y, z);
    if v.is_finite() {
        Ok(v)
    } else {
        Err(fail(ctx, format!("({x}, {y}, {z}) is not finite")))
    }
}

/// Three numbers as a colour: finite and not negative.
pub(super) fn colour(
    ctx: &NativeCallContext,
    r: &Dynamic,
    g: &Dynamic,
    b: &Dynamic,
) -> Result<Vec3, Box<EvalAltResult>> {
    let c = vec3(ctx, r, g, b)?.as_vec3();
    if c.min_element() < 0.0 {
        return Err(fail(ctx, format!("colour {c} is negative")));
    }
    Ok(c)
}

/// Registers every function scripts may call.
pub(super) fn register(engine: &mut Engine, state: &Shared, origin: DVec3) {
    for (name, kind) in [
        ("point_light", "pointlight"),
        ("spot_light", "spotlight"),
        ("sun_light", "sunlight"),
        ("area_light", "arealight"),
    ] {
        let st = state.clone();
        engine.register_fn(name, move |ctx: NativeCallContext, props: Map| {
            add_object(&ctx, &st, kind, None, &props)
        });
    }
    let st = state.clone();
    engine.register_fn(
        "model",
        move |ctx: NativeCallContext, file: &str, props: Map| {
            let mut props = props;
            props.insert("file".into(), file.into());
            add_object(&ctx, &st, "model", None, &props)
        },
    );
    register_models(engine, state, origin);
    register_model_colors(engine, state);
    register_cameras(engine, state);
    let st = state.clone();
    engine.register_fn(
        "camera",
        move |ctx: NativeCallContext, name: &str, props: Map| {
            add_object(&ctx, &st, "camera", Some(name), &props).map(|_| ())
        },
    );
    let st = state.clone();
    engine.register_fn("rand", move || FLOAT::from(lock(&st).rng.next_f32()));
    let st = state.clone();
    engine.register_fn(
        "rand_range",
        move |ctx: NativeCallContext, lo: Dynamic, hi: Dynamic| {
            let (Some(lo), Some(hi)) = (number(&lo), number(&hi)) else {
                return Err(fail(&ctx, "rand_range expects two numbers"));
            };
            Ok::<FLOAT, Box<EvalAltResult>>(lo + (hi - lo) * FLOAT::from(lock(&st).rng.next_f32()))
        },
    );
    let st = state.clone();
    engine.register_fn("light_count", move || {
        let s = lock(&st);
        (if s.loading {
            s.lights_before + s.desc.lights.len()
        } else {
            s.lights.len()
        }) as INT
    });
    let st = state.clone();
    engine.register_fn("light_position", move |ctx: NativeCallContext, i: INT| {
        let s = lock(&st);
        let i = light_index(&ctx, &s, i)?;
        // Positions are stored relative to the scene's origin; a sun's direction is not a point.
        let world = match &s.lights[i] {
            Light::Point(l) => origin + l.position.as_dvec3(),
            Light::Spot(l) => origin + l.position.as_dvec3(),
            Light::Area(l) => origin + l.position.as_dvec3(),
            Light::Sun(l) => l.direction.as_dvec3(),
        };
        Ok::<Array, Box<EvalAltResult>>(array3(world))
    });
    let st = state.clone();
    engine.register_fn(
        "set_light_position",
        move |ctx: NativeCallContext, i: INT, x: Dynamic, y: Dynamic, z: Dynamic| {
            let p = (vec3(&ctx, &x, &y, &z)? - origin).as_vec3();
            let mut s = lock(&st);
            let i = light_index(&ctx, &s, i)?;
            s.touched[i] = true;
            match &mut s.lights[i] {
                Light::Point(l) => l.position = p,
                Light::Spot(l) => l.position = p,
                Light::Area(l) => l.position = p,
                Light::Sun(_) => {
                    return Err(fail(
                        &ctx,
                        format!("light {i} is a sun: it has a direction, not a position"),
                    ))
                }
            }
            Ok::<(), Box<EvalAltResult>>(())
        },
    );
    let st = state.clone();
    engine.register_fn(
        "set_light_direction",
        move |ctx: NativeCallContext, i: INT, x: Dynamic, y: Dynamic, z: Dynamic| {
            let d = vec3(&ctx, &x, &y, &z)?.as_vec3();
            let Some(d) = d.try_normalize() else {
                return Err(fail(&ctx, "a light's direction must not be zero"));
            };
            let mut s = lock(&st);
            let i = light_index(&ctx, &s, i)?;
            s.touched[i] = true;
            match &mut s.lights[i] {
                Light::Sun(l) => l.direction = d,
                Light::Spot(l) => l.direction = d,
                _ => {
                    return Err(fail(
                        &ctx,
                        format!("light {i} has no direction (suns and spots do)"),
                    ))
                }
            }
            Ok::<(), Box<EvalAltResult>>(())
        },
    );
    let st = state.clone();
    engine.register_fn(
        "set_light_color",
        move |ctx: NativeCallContext, i: INT, r: Dynamic, g: Dynamic, b: Dynamic| {
            let c = colour(&ctx, &r, &g, &b)?;
            let mut s = lock(&st);
            let i = light_index(&ctx, &s, i)?;
            s.touched[i] = true;
            match &mut s.lights[i] {
                Light::Sun(l) => l.color = c,
                Light::Spot(l) => l.color = c,
                Light::Point(l) => l.color = c,
                Light::Area(l) => l.emission = c,
            }
            Ok::<(), Box<EvalAltResult>>(())
        },
    );
    let st = state.clone();
    engine.register_fn(
        "set_light_on",
        move |ctx: NativeCallContext, i: INT, on: bool| {
            let mut s = lock(&st);
            let i = light_index(&ctx, &s, i)?;
            s.touched[i] = true;
            s.on[i] = on;
            Ok::<(), Box<EvalAltResult>>(())
        },
    );
}

/// The functions on model placements: their count and bounds, and per frame
/// their transforms.
pub(super) fn register_models(engine: &mut Engine, state: &Shared, origin: DVec3) {
    let st = state.clone();
    engine.register_fn("model_count", move || {
        let s = lock(&st);
        (if s.loading {
            s.models_before.len() + s.desc.models.len()
        } else {
            s.transforms.len()
        }) as INT
    });
    let st = state.clone();
    engine.register_fn("scene_bounds", move |ctx: NativeCallContext| {
        let mut s = lock(&st);
        let bounds = if s.loading {
            s.placed_bounds()
                .map_err(|e| fail(&ctx, format!("scene_bounds: {e}")))?
        } else {
            s.scene_bounds
        };
        if bounds.is_empty() {
            return Err(fail(&ctx, "scene_bounds: no model is placed yet"));
        }
        let mut map = Map::new();
        map.insert("min".into(), array3(origin + bounds.min.as_dvec3()).into());
        map.insert("max".into(), array3(origin + bounds.max.as_dvec3()).into());
        Ok::<Map, Box<EvalAltResult>>(map)
    });
    let st = state.clone();
    engine.register_fn("model_position", move |ctx: NativeCallContext, i: INT| {
        let s = lock(&st);
        let i = frame_index(&ctx, &s, ("model", s.transforms.len()), i)?;
        let p = s.transforms[i].w_axis.truncate().as_dvec3();
        Ok::<Array, Box<EvalAltResult>>(array3(origin + p))
    });
    let st = state.clone();
    engine.register_fn(
        "set_model_transform",
        move |ctx: NativeCallContext, i: INT, props: Map| {
            let mut s = lock(&st);
            let i = frame_index(&ctx, &s, ("model", s.transforms.len()), i)?;
            let transform = placement_transform(&props, origin)
                .map_err(|m| fail(&ctx, format!("set_model_transform: {m}")))?;
            if !transform.is_finite() {
                return Err(fail(
                    &ctx,
                    "set_model_transform: the transform is not finite",
                ));
            }
            s.transforms[i] = transform;
            Ok::<(), Box<EvalAltResult>>(())
        },
    );
}

/// `set_model_color`: a placement's colour override per frame.
pub(super) fn register_model_colors(engine: &mut Engine, state: &Shared) {
    let st = state.clone();
    engine.register_fn(
        "set_model_color",
        move |ctx: NativeCallContext, i: INT, r: Dynamic, g: Dynamic, b: Dynamic| {
            let c = colour(&ctx, &r, &g, &b)?;
            let mut s = lock(&st);
            let i = frame_index(&ctx, &s, ("model", s.colors.len()), i)?;
            s.colors[i] = Some(c);
            Ok::<(), Box<EvalAltResult>>(())
        },
    );
}

/// `set_camera`: a camera's pose (and field of view) per frame.
pub(super) fn register_cameras(engine: &mut Engine, state: &Shared) {
    let st = state.clone();
    engine.register_fn(
        "set_camera",
        move |ctx: NativeCallContext, name: &str, props: Map| {
            let mut s = lock(&st);
            if s.loading {
                return Err(fail(
                    &ctx,
                    "cameras are moved in init or update; at load, add them with camera(name, #{...})",
                ));
            }
            let Some(i) = s.cameras.iter().position(|c| c.name == name) else {
                let names: Vec<&str> = s.cameras.iter().map(|c| c.name.as_str()).collect();
                return Err(fail(
                    &ctx,
                    format!("no camera '{name}': the scene has {}", names.join(", ")),
                ));
            };
            if !props.contains_key("position") {
                return Err(fail(&ctx, "set_camera needs a 'position'"));
            }
            let desc = read_object(
                &ctx,
                &s,
                "set_camera",
                ("camera", Some(name)),
                &props,
                &["position", "target", "orientation", "fov", "fov_deg"],
            )?;
            let set = &desc.cameras[0];
            let camera = &mut s.cameras[i];
            camera.position = set.position;
            camera.orientation = set.orientation;
            if props.contains_key("fov") || props.contains_key("fov_deg") {
                camera.fov_y = set.fov_y;
            }
            camera.path.clear();
            s.camera_set[i] = true;
            Ok::<(), Box<EvalAltResult>>(())
        },
    );
}
