//! `weft graph check|plan|dot`.

use anyhow::{bail, Context, Result};
use clap::{Args, Subcommand};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;
use weft_graph::{CompileOptions, Diagnostic, Extent, LoadedGraph};

/// Graph subcommands.
#[derive(Subcommand)]
pub enum GraphCommand {
    /// Validate graph files; exit 1 on any error (messages on stderr).
    Check {
        #[arg(required = true)]
        files: Vec<PathBuf>,
    },
    /// Compile a graph and print its plan: pass order, culled passes, barriers, render-pass ops.
    Plan {
        file: PathBuf,
        #[command(flatten)]
        target: Target,
        /// Print the plan as JSON with a `stats` object.
        #[arg(long)]
        json: bool,
    },
    /// Print the graph as Graphviz DOT (culled passes greyed).
    Dot {
        file: PathBuf,
        #[command(flatten)]
        target: Target,
    },
}

/// What a graph is compiled for.
#[derive(Args)]
pub struct Target {
    /// Output size, WIDTHxHEIGHT.
    #[arg(long, default_value = "1280x720", value_parser = parse_size)]
    size: Extent,
    /// Features on (comma-separated); `!name` turns off a graph default.
    #[arg(long, value_delimiter = ',')]
    features: Vec<String>,
    /// Light count for buffer size expressions.
    #[arg(long, default_value_t = 1)]
    lights: u32,
}

fn parse_size(text: &str) -> Result<Extent, String> {
    let (w, h) = text
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("expected WIDTHxHEIGHT, found \"{text}\""))?;
    let parse = |v: &str| -> Result<u32, String> {
        match v.trim().parse::<u32>() {
            Ok(n) if (1..=16384).contains(&n) => Ok(n),
            _ => Err(format!("size must be 1..=16384, found \"{v}\"")),
        }
    };
    Ok(Extent {
        width: parse(w)?,
        height: parse(h)?,
    })
}

fn print_diagnostics(diags: &[Diagnostic]) {
    for d in diags {
        eprintln!("{d}");
    }
}

fn compile(file: &Path, target: &Target) -> Result<(LoadedGraph, weft_graph::Plan, f64)> {
    let graph = weft_graph::load(file);
    let options = CompileOptions {
        extent: target.size,
        features: graph.features(&target.features),
        lights: target.lights,
        ..CompileOptions::default()
    };
    let start = Instant::now();
    let result = weft_graph::compile(&graph, &options);
    let compile_us = start.elapsed().as_secs_f64() * 1e6;
    match result {
        Ok(plan) => Ok((graph, plan, compile_us)),
        Err(diags) => {
            print_diagnostics(&diags);
            let errors = diags.iter().filter(|d| d.is_error()).count();
            bail!(
                "{} failed to compile with {errors} error(s)",
                file.display()
            )
        }
    }
}

/// Runs a graph subcommand.
pub fn run(cmd: GraphCommand) -> Result<ExitCode> {
    match cmd {
        GraphCommand::Check { files } => {
            let mut failed = false;
            for file in &files {
                let graph = weft_graph::load(file);
                let diags = weft_graph::check(&graph);
                print_diagnostics(&diags);
                let errors = diags.iter().filter(|d| d.is_error()).count();
                let warnings = diags.len() - errors;
                if errors > 0 {
                    failed = true;
                    eprintln!(
                        "{}: {errors} error(s), {warnings} warning(s)",
                        file.display()
                    );
                } else {
                    eprintln!("{}: ok ({warnings} warning(s))", file.display());
                }
            }
            Ok(if failed {
                ExitCode::FAILURE
            } else {
                ExitCode::SUCCESS
            })
        }
        GraphCommand::Plan { file, target, json } => {
            let (_, plan, compile_us) = compile(&file, &target)?;
            if json {
                let mut value = serde_json::to_value(&plan).context("serialising the plan")?;
                value["stats"] = serde_json::to_value(plan.stats(compile_us))?;
                println!("{}", serde_json::to_string_pretty(&value)?);
            } else {
                print!("{}", weft_graph::text::render(&plan));
                print_diagnostics(&plan.warnings);
            }
            Ok(ExitCode::SUCCESS)
        }
        GraphCommand::Dot { file, target } => {
            let (graph, plan, _) = compile(&file, &target)?;
            print!("{}", weft_graph::dot::render(&graph, &plan));
            Ok(ExitCode::SUCCESS)
        }
    }
}
