//! `conduit convert`: mesh files to STL, 3MF or OBJ, many in parallel.
//!
//! An input may be a folder: its mesh files (by extension, not recursive) in name order. Each
//! conversion prints one line (`IN -> OUT: N objects, M triangles`) and a failed one its error,
//! one line each, so the error lines count the failures (no extra summary line; `--json` has
//! the count).

use super::{Failure, args::ConvertArgs, progress};
use anyhow::Context;
use conduit::geom::Tolerances;
use conduit::scene::{FileKind, LoadOptions, MeshFormat, OutputSet, load_scene, save};
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// One validated conversion job.
struct Job {
    input: PathBuf,
    output: PathBuf,
    format: MeshFormat,
}

pub(crate) fn run(args: ConvertArgs) -> Result<(), Failure> {
    let inputs = expand_folders(&args.inputs)?;
    let jobs = plan(&args, &inputs)?;
    // No output may overwrite an input (`convert x.stl -o x.stl`, or a batch whose folder holds
    // the inputs): refused before any work.
    let inputs = OutputSet::new(&inputs);
    for job in &jobs {
        inputs.check(&job.output)?;
    }
    let opts = super::load_options();
    let bar = progress::bar(jobs.len(), "converting");
    let results: Vec<anyhow::Result<Converted>> = jobs
        .par_iter()
        .map(|job| {
            let r = convert_one(job, &opts, args.repair);
            bar.inc(1);
            r
        })
        .collect();
    bar.finish_and_clear();
    let failed = results.iter().filter(|r| r.is_err()).count();
    if args.json {
        let done: Vec<serde_json::Value> = jobs
            .iter()
            .zip(&results)
            .map(|(job, r)| match r {
                Ok(c) => serde_json::json!({
                    "input": job.input.display().to_string(),
                    "output": job.output.display().to_string(),
                    "objects": c.objects,
                    "triangles": c.triangles,
                }),
                Err(e) => serde_json::json!({
                    "input": job.input.display().to_string(),
                    "error": format!("{e:#}"),
                }),
            })
            .collect();
        super::print_json(&serde_json::json!({
            "outputs": super::paths(
                jobs.iter()
                    .zip(&results)
                    .filter(|(_, r)| r.is_ok())
                    .map(|(j, _)| j.output.as_path())
            ),
            "converted": jobs.len() - failed,
            "failed": failed,
            "conversions": done,
        }))?;
    }
    for (job, r) in jobs.iter().zip(&results) {
        match r {
            Ok(c) if args.json => {
                for w in &c.warnings {
                    warnln!("{}: {w}", job.input.display());
                }
            }
            Ok(c) => {
                for w in &c.warnings {
                    warnln!("{}: {w}", job.input.display());
                }
                outln!(
                    "{} -> {}: {} object{}, {} triangles",
                    job.input.display(),
                    job.output.display(),
                    c.objects,
                    if c.objects == 1 { "" } else { "s" },
                    c.triangles
                )?
            }
            Err(e) => errorln!("{e:#}"),
        }
    }
    if failed > 0 {
        return Err(Failure::Reported);
    }
    Ok(())
}

/// What one conversion wrote.
struct Converted {
    objects: usize,
    triangles: usize,
    /// The reader's warnings, printed to stderr.
    warnings: Vec<String>,
}

/// The inputs with every folder replaced by its mesh files (known extensions, not recursive,
/// in name order); a folder without any is an error naming it.
fn expand_folders(inputs: &[PathBuf]) -> Result<Vec<PathBuf>, Failure> {
    let mut out = Vec::with_capacity(inputs.len());
    for input in inputs {
        if !input.is_dir() {
            out.push(input.clone());
            continue;
        }
        let entries = std::fs::read_dir(input)
            .with_context(|| format!("{}: cannot read the folder", input.display()))?;
        let mut meshes: Vec<PathBuf> = entries
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| {
                p.is_file()
                    && matches!(
                        FileKind::from_extension(p),
                        Some(
                            FileKind::Stl
                                | FileKind::ThreeMf
                                | FileKind::Obj
                                | FileKind::Off
                                | FileKind::Ply
                        )
                    )
            })
            .collect();
        if meshes.is_empty() {
            return Err(Failure::Usage(format!(
                "{}: the folder holds no mesh files (.stl, .3mf, .obj, .off, .ply)",
                input.display()
            )));
        }
        meshes.sort();
        out.extend(meshes);
    }
    Ok(out)
}

/// Turns the arguments into jobs, rejecting ambiguous or colliding outputs before any work runs.
fn plan(args: &ConvertArgs, inputs: &[PathBuf]) -> Result<Vec<Job>, Failure> {
    let ascii = |f: MeshFormat| {
        if args.ascii && f == MeshFormat::Stl {
            MeshFormat::StlAscii
        } else {
            f
        }
    };
    if let Some(out) = &args.output {
        if inputs.len() != 1 {
            return Err(Failure::Usage(
                "-o takes exactly one input; use --to and --out-dir for several".into(),
            ));
        }
        let format = MeshFormat::from_path(out).ok_or_else(|| {
            Failure::Usage(format!(
                "{}: output extension must be .stl, .3mf or .obj",
                out.display()
            ))
        })?;
        return Ok(vec![Job {
            input: inputs[0].clone(),
            output: out.clone(),
            format: ascii(format),
        }]);
    }
    let (Some(format), Some(dir)) = (args.to, args.out_dir.as_ref()) else {
        return Err(Failure::Usage(
            "give -o OUT, or --to FORMAT with --out-dir DIR".into(),
        ));
    };
    // A missing output folder is made, as every command's --out-dir does.
    std::fs::create_dir_all(dir)
        .with_context(|| format!("{}: cannot create the output folder", dir.display()))?;
    let mut seen: BTreeMap<PathBuf, &Path> = BTreeMap::new();
    let mut jobs = Vec::with_capacity(args.inputs.len());
    for input in inputs {
        let stem = input
            .file_stem()
            .ok_or_else(|| Failure::Usage(format!("{}: not a file name", input.display())))?;
        let output = dir.join(stem).with_extension(format.extension());
        if let Some(other) = seen.insert(output.clone(), input) {
            return Err(Failure::Usage(format!(
                "{} and {} would both be written to {}",
                other.display(),
                input.display(),
                output.display()
            )));
        }
        jobs.push(Job {
            input: input.clone(),
            output,
            format: ascii(format),
        });
    }
    Ok(jobs)
}

fn convert_one(job: &Job, opts: &LoadOptions, repair: bool) -> anyhow::Result<Converted> {
    let (mut scene, warnings) = load_scene(&job.input, opts)?;
    if scene.triangle_count() == 0 {
        anyhow::bail!("{}: no triangles to convert", job.input.display());
    }
    if repair {
        let tol = Tolerances::default();
        for o in &mut scene.objects {
            o.mesh.repair(&tol);
        }
    }
    save(&scene, &job.output, job.format)
        .with_context(|| format!("converting {}", job.input.display()))?;
    Ok(Converted {
        objects: scene.objects.len(),
        triangles: scene.triangle_count(),
        warnings,
    })
}
