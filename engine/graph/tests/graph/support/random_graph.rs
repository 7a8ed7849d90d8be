//! Random but valid graphs as RON text, for property tests and benchmarks: raster,
//! fullscreen, compute and copy passes over random formats and sizes, sampled and
//! storage reads, read-modify-write attachments, history images, extra `after`
//! edges and feature-conditional passes whose readers are conditional too.

/// A small deterministic generator (SplitMix64), so a failing seed reproduces.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Rng(seed)
    }
    pub fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    pub fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
    pub fn chance(&mut self, percent: usize) -> bool {
        self.below(100) < percent
    }
}

const COLOR: &[&str] = &[
    "R8G8B8A8_UNORM",
    "R16G16B16A16_SFLOAT",
    "R16G16_SFLOAT",
    "R8_UNORM",
];
const STORAGE: &[&str] = &["R8G8B8A8_UNORM", "R16G16B16A16_SFLOAT", "R32_SFLOAT"];
const DEPTH: &[&str] = &["D32_SFLOAT", "D16_UNORM"];
const SIZES: &[&str] = &["Output", "Scale(0.5, 0.5)"];

struct Res {
    name: String,
    storage: bool,
    buffer: bool,
    depth: bool,
    size: usize,
    condition: Option<String>,
    writer: String,
    read: bool,
}

/// A random graph with `passes` passes (plus a final output pass) and the features it mentions.
pub fn random_graph(seed: u64, passes: usize) -> String {
    let mut rng = Rng::new(seed);
    let mut resources: Vec<String> = Vec::new();
    let mut pass_text: Vec<String> = Vec::new();
    let mut pool: Vec<Res> = Vec::new();
    let mut history: Vec<String> = Vec::new();
    for i in 0..passes {
        let name = format!("p{i}");
        let condition = rng.chance(10).then(|| format!("f{}", rng.below(4)));
        let size = rng.below(SIZES.len());
        let mut fields: Vec<String> = Vec::new();
        let mut reads: Vec<String> = Vec::new();
        let mut storage_reads: Vec<String> = Vec::new();
        // Reads of earlier resources; conditional where their writer is.
        for _ in 0..rng.below(4) {
            if pool.is_empty() {
                break;
            }
            let k = rng.below(pool.len());
            let r = &mut pool[k];
            if r.writer == name
                || reads
                    .iter()
                    .chain(&storage_reads)
                    .any(|x| x.contains(&format!("\"{}\"", r.name)))
            {
                continue;
            }
            let entry = match (&r.condition, &condition) {
                (Some(c), Some(mine)) if c == mine => format!("\"{}\"", r.name),
                (Some(c), _) => format!("(name: \"{}\", enabled_if: [\"{c}\"])", r.name),
                (None, _) => format!("\"{}\"", r.name),
            };
            r.read = true;
            if r.buffer || (r.storage && rng.chance(50)) {
                storage_reads.push(entry);
            } else {
                reads.push(entry);
            }
        }
        let kind = rng.below(10);
        let mut writes: Vec<Res> = Vec::new();
        let mut new_image =
            |rng: &mut Rng, formats: &[&str], storage: bool, depth: bool, size: usize| {
                let rname = format!("r{}", resources.len());
                let format = formats[rng.below(formats.len())];
                resources.push(format!(
                    "Image(name: \"{rname}\", format: {format}, size: {})",
                    SIZES[size]
                ));
                Res {
                    name: rname,
                    storage,
                    buffer: false,
                    depth,
                    size,
                    condition: None,
                    writer: String::new(),
                    read: false,
                }
            };
        match kind {
            0..=3 => {
                fields.push("kind: Raster".into());
                fields.push("shaders: (vertex: \"v.vert\", fragment: \"f.frag\")".into());
                fields.push("draw: Meshes(All)".into());
                let mut colors = Vec::new();
                for _ in 0..1 + rng.below(2) {
                    let r = new_image(&mut rng, COLOR, false, false, size);
                    colors.push(format!(
                        "(image: \"{}\", load: Clear([0.0, 0.0, 0.0, 0.0]))",
                        r.name
                    ));
                    writes.push(r);
                }
                fields.push(format!("color: [{}]", colors.join(", ")));
                if rng.chance(50) {
                    let r = new_image(&mut rng, DEPTH, false, true, size);
                    fields.push(format!(
                        "depth: (image: \"{}\", load: Clear([0.0]))",
                        r.name
                    ));
                    writes.push(r);
                }
            }
            4..=5 => {
                fields.push("kind: Fullscreen".into());
                fields.push("shaders: (fragment: \"f.frag\")".into());
                // Read-modify-write an unread colour image, ordered after its writer.
                let target = pool.iter_mut().find(|r| {
                    !r.read
                        && !r.depth
                        && !r.buffer
                        && !r.storage
                        && r.condition == condition
                        && r.size == size
                });
                if let (Some(t), true) = (target, rng.chance(40)) {
                    t.read = true;
                    fields.push(format!(
                        "color: [(image: \"{}\", load: Load, blend: Additive)]",
                        t.name
                    ));
                    fields.push(format!("after: [\"{}\"]", t.writer));
                } else if let (Some(h), true) = (history.pop(), size == 0) {
                    fields.push(format!("color: [(image: \"{h}\")]"));
                } else {
                    let r = new_image(&mut rng, COLOR, false, false, size);
                    fields.push(format!("color: [(image: \"{}\")]", r.name));
                    writes.push(r);
                }
                if rng.chance(10) {
                    let h = format!("h{i}");
                    resources.push(format!(
                        "Image(name: \"{h}\", format: R16G16B16A16_SFLOAT, history: true)"
                    ));
                    reads.push(format!("\"{h}\""));
                    history.push(h);
                }
            }
            6..=8 => {
                fields.push("kind: Compute".into());
                fields.push("shaders: (compute: \"c.comp\")".into());
                fields.push("dispatch: Output(8, 8)".into());
                if rng.chance(30) {
                    let rname = format!("r{}", resources.len());
                    resources.push(format!(
                        "Buffer(name: \"{rname}\", size: \"pixels * 4 + $lights * 16\")"
                    ));
                    fields.push(format!("storage_write: [\"{rname}\"]"));
                    writes.push(Res {
                        name: rname,
                        storage: true,
                        buffer: true,
                        depth: false,
                        size,
                        condition: None,
                        writer: String::new(),
                        read: false,
                    });
                } else {
                    let r = new_image(&mut rng, STORAGE, true, false, size);
                    fields.push(format!("storage_write: [\"{}\"]", r.name));
                    writes.push(r);
                }
            }
            _ => {
                let source = pool
                    .iter()
                    .position(|r| !r.buffer && !r.depth && r.condition.is_none());
                match source {
                    Some(k) if rng.chance(70) => {
                        pool[k].read = true;
                        let src = pool[k].name.clone();
                        let src_size = pool[k].size;
                        fields.push("kind: Copy".into());
                        fields.push(format!("src: \"{src}\""));
                        let rname = format!("r{}", resources.len());
                        resources.push(format!(
                            "Image(name: \"{rname}\", format: R8G8B8A8_UNORM, size: {})",
                            SIZES[src_size]
                        ));
                        fields.push(format!("dst: \"{rname}\""));
                        writes.push(Res {
                            name: rname,
                            storage: false,
                            buffer: false,
                            depth: false,
                            size: src_size,
                            condition: None,
                            writer: String::new(),
                            read: false,
                        });
                        reads.clear();
                        storage_reads.clear();
                    }
                    _ => {
                        fields.push("kind: Compute".into());
                        fields.push("shaders: (compute: \"c.comp\")".into());
                        fields.push("dispatch: Groups(4, 4, 1)".into());
                        let r = new_image(&mut rng, STORAGE, true, false, size);
                        fields.push(format!("storage_write: [\"{}\"]", r.name));
                        writes.push(r);
                    }
                }
            }
        }
        if !reads.is_empty() {
            fields.push(format!("sampled: [{}]", reads.join(", ")));
        }
        if !storage_reads.is_empty() {
            fields.push(format!("storage_read: [{}]", storage_reads.join(", ")));
        }
        if let Some(c) = &condition {
            fields.push(format!("enabled_if: [\"{c}\"]"));
        }
        if i > 0 && rng.chance(15) && !fields.iter().any(|f| f.starts_with("after")) {
            fields.push(format!("after: [\"p{}\"]", rng.below(i)));
        }
        pass_text.push(format!("Pass(name: \"{name}\", {})", fields.join(", ")));
        for mut w in writes {
            w.condition = condition.clone();
            w.writer = name.clone();
            pool.push(w);
        }
    }
    // History images nobody wrote get a writer so they are not read before any write.
    for h in history.drain(..) {
        pass_text.push(format!(
            "Pass(name: \"write_{h}\", kind: Fullscreen, shaders: (fragment: \"f.frag\"), color: [(image: \"{h}\")])"
        ));
    }
    let finals: Vec<String> = pool
        .iter()
        .filter(|r| !r.buffer && rng.chance(30))
        .map(|r| match &r.condition {
            Some(c) => format!("(name: \"{}\", enabled_if: [\"{c}\"])", r.name),
            None => format!("\"{}\"", r.name),
        })
        .collect();
    resources.push("Image(name: \"out\", format: R8G8B8A8_SRGB)".into());
    pass_text.push(format!(
        "Pass(name: \"final\", kind: Fullscreen, shaders: (fragment: \"f.frag\"), sampled: [{}], color: [(image: \"out\")])",
        finals.join(", ")
    ));
    format!(
        "Graph(\n  params: {{ \"lights\": 8 }},\n  resources: [\n    {}\n  ],\n  passes: [\n    {}\n  ],\n  output: \"out\",\n)\n",
        resources.join(",\n    "),
        pass_text.join(",\n    ")
    )
}
