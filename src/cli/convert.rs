//! `conduit convert`: mesh files to STL, 3MF or OBJ, many in parallel.

use super::{Failure, args::ConvertArgs, progress};
use anyhow::Context;
use conduit::geom::Tolerances;
use conduit::scene::{LoadOptions, MeshFormat, OutputSet, load_scene, save};
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
    let jobs = plan(&args)?;
    // No output may overwrite an input (`convert x.stl -o x.stl`, or a batch whose folder holds
    // the inputs): refused before any work.
    let inputs = OutputSet::new(&args.inputs);
    for job in &jobs {
        inputs.check(&job.output)?;
    }
    let opts = LoadOptions::default();
    let bar = progress::bar(jobs.len(), "converting");
    let results: Vec<Result<(), anyhow::Error>> = jobs
        .par_iter()
        .map(|job| {
            let r = convert_one(job, &opts, args.repair);
            bar.inc(1);
            r
        })
        .collect();
    bar.finish_and_clear();
    let mut failed = 0;
    for r in &results {
        if let Err(e) = r {
            failed += 1;
            eprintln!("error: {e:#}");
        }
    }
    if failed > 0 {
        eprintln!("{failed} of {} conversions failed", jobs.len());
        return Err(Failure::Reported);
    }
    Ok(())
}

/// Turns the arguments into jobs, rejecting ambiguous or colliding outputs before any work runs.
fn plan(args: &ConvertArgs) -> Result<Vec<Job>, Failure> {
    let ascii = |f: MeshFormat| {
        if args.ascii && f == MeshFormat::Stl {
            MeshFormat::StlAscii
        } else {
            f
        }
    };
    if let Some(out) = &args.output {
        if args.inputs.len() != 1 {
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
            input: args.inputs[0].clone(),
            output: out.clone(),
            format: ascii(format),
        }]);
    }
    let (Some(format), Some(dir)) = (args.to, args.out_dir.as_ref()) else {
        return Err(Failure::Usage(
            "give -o OUT, or --to FORMAT with --out-dir DIR".into(),
        ));
    };
    if !dir.is_dir() {
        return Err(Failure::Usage(format!(
            "{}: output folder does not exist",
            dir.display()
        )));
    }
    let mut seen: BTreeMap<PathBuf, &Path> = BTreeMap::new();
    let mut jobs = Vec::with_capacity(args.inputs.len());
    for input in &args.inputs {
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

fn convert_one(job: &Job, opts: &LoadOptions, repair: bool) -> anyhow::Result<()> {
    let (mut scene, _warnings) = load_scene(&job.input, opts)?;
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
    Ok(())
}
