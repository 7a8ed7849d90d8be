//! The light tree (`light_choice` 2; engine/render/src/light_tree.rs,
//! shaders/pathtrace/light_tree.glsl) among many lights: 400 point lights of
//! short range over a floor, direct light only. Uniform choice spends most
//! samples on lights out of reach; the tree picks among the lights that
//! reach each point. Two seeds of each at 64 spp give each estimator's
//! per-pixel variance (half the squared difference of the two images),
//! and the tree's must be under a tenth of uniform choice's (measured
//! 70x less with the Sobol sampler, 53x with independent numbers). The
//! tree's mean luminance must be within three standard errors of uniform
//! choice's at 1,024 spp (measured 0.6% apart, the standard error 1.2%).

use super::*;

fn many_lights_scene() -> PathBuf {
    let dir = temp_dir("many-lights");
    std::fs::write(
        dir.join("floor.obj"),
        "mtllib floor.mtl\nusemtl white\nv -10 0 -10\nv 10 0 -10\nv 10 0 10\nv -10 0 10\nvn 0 1 0\n\
         f 1//1 4//1 3//1\nf 1//1 3//1 2//1\n",
    )
    .expect("obj");
    std::fs::write(dir.join("floor.mtl"), "newmtl white\nKd 0.8 0.8 0.8\n").expect("mtl");
    let scene = dir.join("many-lights.scene");
    std::fs::write(
        &scene,
        "model\n{\n\tfile \"floor.obj\"\n}\n\
         pointlights\n{\n\tcount 400\n\tseed 3\n\tmin -9 0.2 -9\n\tmax 9 1 9\n\tcolor_min 0.2 0.2 0.2\n\
         \tcolor_max 1 1 1\n\tradius 1 2\n\tattenuation 1 0 1\n}\n\
         camera\n{\n\tposition 0 14 0.01\n\ttarget 0 0 0\n\tfov_deg 70\n}\n",
    )
    .expect("scene");
    scene
}

#[test]
fn the_light_tree_agrees_with_uniform_choice_among_many_lights_with_far_less_noise() {
    const SIZE: u32 = 32;
    let scene = many_lights_scene();
    let render = |light_choice: f64, seed: f64| {
        let params = [
            ("max_depth", 2.0),
            ("light_choice", light_choice),
            ("seed", seed),
        ];
        render_hdr(&scene, "pathtrace.ron", SIZE, Some(64), &params, &[])
    };
    let uniform = [render(0.0, 1.0), render(0.0, 2.0)];
    let tree = [render(2.0, 1.0), render(2.0, 2.0)];
    let variance = |pair: &[Hdr; 2]| {
        let n = pair[0].pixels.len() as f64;
        pair[0]
            .pixels
            .iter()
            .zip(&pair[1].pixels)
            .map(|(a, b)| {
                (0..3)
                    .map(|c| f64::from(a[c] - b[c]).powi(2) / 2.0)
                    .sum::<f64>()
            })
            .sum::<f64>()
            / n
    };
    let mean_tree = (luminance(tree[0].mean()) + luminance(tree[1].mean())) / 2.0;
    let converged = render_hdr(
        &scene,
        "pathtrace.ron",
        SIZE,
        Some(1024),
        &[("max_depth", 2.0), ("light_choice", 0.0), ("seed", 3.0)],
        &[],
    );
    let mean_uniform = luminance(converged.mean());
    let (var_uniform, var_tree) = (variance(&uniform), variance(&tree));
    // Of the 1,024-spp image's mean luminance: its pixels' variance is the
    // 64-spp pair's over 16.
    let luminance_variance = uniform[0]
        .pixels
        .iter()
        .zip(&uniform[1].pixels)
        .map(|(a, b)| {
            let l = |p: &[f32; 3]| luminance(p.map(f64::from));
            (l(a) - l(b)).powi(2) / 2.0
        })
        .sum::<f64>()
        / f64::from(SIZE * SIZE);
    let standard_error = (luminance_variance / 16.0 / f64::from(SIZE * SIZE)).sqrt();
    println!(
        "mean luminance: uniform at 1,024 spp {mean_uniform:.4} (standard error {standard_error:.4}), tree {mean_tree:.4}; \
         per-pixel variance at 64 spp: uniform {var_uniform:.4e}, tree {var_tree:.4e} ({:.1}x less)",
        var_uniform / var_tree
    );
    assert!(mean_uniform > 0.1, "the floor is lit: {mean_uniform}");
    assert!(
        (mean_tree - mean_uniform).abs() < 3.0 * standard_error,
        "means: tree {mean_tree} vs uniform {mean_uniform}"
    );
    assert!(
        var_tree < var_uniform / 10.0,
        "variance: tree {var_tree} vs uniform {var_uniform}"
    );
}
