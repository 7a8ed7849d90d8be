//! Fits the LTC tables the raster passes' area lights use and writes them to
//! `engine/ltc/tables/ltc_tables.txt` (or the path given):
//! `cargo run -p weft-ltc --release --bin ltc-fit [-- OUT]` (`make ltc-tables`).

use anyhow::Context;
use weft_ltc::lobe::{BlinnPhong, Ggx};
use weft_ltc::tables::{write, Tables};
use weft_ltc::{blinn_phong_exponent, fit, TABLE_SIZE};

fn main() -> anyhow::Result<()> {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "engine/ltc/tables/ltc_tables.txt".to_string());
    let started = std::time::Instant::now();
    let (ggx, blinn_phong) = std::thread::scope(|s| {
        let ggx = s.spawn(|| fit::fit_table(|r| Ggx { alpha: r * r }));
        let blinn_phong = s.spawn(|| {
            fit::fit_table(|r| BlinnPhong {
                exponent: blinn_phong_exponent(r),
            })
        });
        (ggx.join(), blinn_phong.join())
    });
    let tables = Tables {
        ggx: ggx.map_err(|_| anyhow::anyhow!("the GGX fit panicked"))?,
        blinn_phong: blinn_phong.map_err(|_| anyhow::anyhow!("the Blinn-Phong fit panicked"))?,
    };
    std::fs::write(&out, write(&tables)).with_context(|| format!("writing {out}"))?;
    let n = TABLE_SIZE;
    eprintln!(
        "wrote {out}: two {n}x{n} tables in {:.1} s",
        started.elapsed().as_secs_f64()
    );
    Ok(())
}
