//! Fits the LTC tables the raster passes' area lights use and integrates the
//! GGX albedo table energy compensation reads, and writes them to
//! `engine/ltc/tables/ltc_tables.txt` and `ggx_albedo.txt` (or into the
//! directory given): `cargo run -p weft-ltc --release --bin ltc-fit [-- DIR]`
//! (`make ltc-tables`).

use anyhow::Context;
use std::path::PathBuf;
use weft_ltc::energy::AlbedoTable;
use weft_ltc::lobe::{BlinnPhong, Ggx};
use weft_ltc::tables::{write, Tables};
use weft_ltc::{blinn_phong_exponent, fit, TABLE_SIZE};

fn main() -> anyhow::Result<()> {
    let dir = PathBuf::from(
        std::env::args()
            .nth(1)
            .unwrap_or_else(|| "engine/ltc/tables".to_string()),
    );
    let started = std::time::Instant::now();
    let (ggx, blinn_phong, albedo) = std::thread::scope(|s| {
        let albedo = s.spawn(AlbedoTable::compute);
        let ggx = s.spawn(|| fit::fit_table(|r| Ggx { alpha: r * r }));
        let blinn_phong = s.spawn(|| {
            fit::fit_table(|r| BlinnPhong {
                exponent: blinn_phong_exponent(r),
            })
        });
        (ggx.join(), blinn_phong.join(), albedo.join())
    });
    let albedo = albedo.map_err(|_| anyhow::anyhow!("the albedo integration panicked"))?;
    let tables = Tables {
        ggx: ggx.map_err(|_| anyhow::anyhow!("the GGX fit panicked"))?,
        blinn_phong: blinn_phong.map_err(|_| anyhow::anyhow!("the Blinn-Phong fit panicked"))?,
    };
    for (name, text) in [
        ("ltc_tables.txt", write(&tables)),
        ("ggx_albedo.txt", albedo.write()),
    ] {
        let out = dir.join(name);
        std::fs::write(&out, text).with_context(|| format!("writing {}", out.display()))?;
    }
    let (n, rows, columns) = (
        TABLE_SIZE,
        weft_ltc::energy::ROWS,
        weft_ltc::energy::COLUMNS,
    );
    eprintln!(
        "wrote {}: two {n}x{n} LTC tables and a {rows}x{columns} albedo table in {:.1} s",
        dir.display(),
        started.elapsed().as_secs_f64()
    );
    Ok(())
}
