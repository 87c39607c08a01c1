//! `rins data fetch` and `rins data list`: the recorded data sets the evaluations read, fetched
//! from their public git repositories into the recordings directory.
//!
//! Each source is cloned shallow and sparse (one commit, only the files a set takes) into
//! `DIR/.sources/<set>`, where a later run finds it again; the set is built in
//! `DIR/.<set>.partial` and renamed into place when complete, so an interrupted fetch leaves
//! either the old set or none, never half of one. What is made of which file, the licences and
//! the origin of the peer figures are in [`rins_eval::data`]; this module runs git and the files.

use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode, Stdio};

use anyhow::{Context, Result, anyhow, bail};
use rins_eval::data::{
    Conversion, DATA_SETS, DataSet, PROVENANCE_FILE, Step, find, mat, names, plan, provenance,
    provenance_commit, pyshoe_mat,
};

use super::progress::Progress;
use crate::cli::{DataFetchArgs, DataListArgs};

/// The first line of a Git LFS pointer: what a repository holds instead of a large file it
/// keeps elsewhere.
const LFS_POINTER: &[u8] = b"version https://git-lfs.github.com/spec/v1";

/// The recordings directory: `--dir`, else `$RINS_DATA_DIR`, else `data/` at the top of the
/// repository, where the evaluations and tests look.
fn recordings_dir(dir: Option<&Path>) -> PathBuf {
    match dir {
        Some(d) => d.to_path_buf(),
        None => {
            let d = rins_eval::datasets::recordings_dir();
            // `<repo>/tools/eval/../../data` reads better resolved.
            match (d.parent().map(Path::canonicalize), d.file_name()) {
                (Some(Ok(parent)), Some(name)) => parent.join(name),
                _ => d,
            }
        }
    }
}

/// The sets named on the command line (every set when none is), or an error naming the unknown.
fn selected(names_given: &[String]) -> Result<Vec<&'static DataSet>> {
    if names_given.is_empty() {
        return Ok(DATA_SETS.iter().collect());
    }
    names_given
        .iter()
        .map(|n| find(n).ok_or_else(|| anyhow!("unknown data set {n:?}; known: {}", names())))
        .collect()
}

/// `--source SET=URL` options as (set, url) pairs.
fn source_overrides(options: &[String]) -> Result<Vec<(&'static str, String)>> {
    options
        .iter()
        .map(|o| {
            let (set, url) = o
                .split_once('=')
                .ok_or_else(|| anyhow!("--source {o:?}: expected SET=URL"))?;
            let set = find(set).ok_or_else(|| {
                anyhow!(
                    "--source {o:?}: unknown data set {set:?}; known: {}",
                    names()
                )
            })?;
            if url.is_empty() {
                bail!("--source {o:?}: empty URL");
            }
            Ok((set.name, url.to_string()))
        })
        .collect()
}

/// How complete a set directory is.
#[derive(Debug, PartialEq, Eq)]
enum State {
    /// No directory.
    Missing,
    /// Some expected files absent: how many, and the first.
    Incomplete { absent: usize, first: String },
    /// Every expected file there; the commit of its provenance note, if it has one.
    Present { commit: Option<String> },
}

fn state(set: &DataSet, set_dir: &Path) -> State {
    if !set_dir.is_dir() {
        return State::Missing;
    }
    let absent: Vec<String> = plan(set)
        .into_iter()
        .flat_map(|s| s.outputs)
        .filter(|o| !set_dir.join(o).is_file())
        .collect();
    if let Some(first) = absent.first() {
        return State::Incomplete {
            absent: absent.len(),
            first: first.clone(),
        };
    }
    let commit = std::fs::read_to_string(set_dir.join(PROVENANCE_FILE))
        .ok()
        .and_then(|t| provenance_commit(&t).map(str::to_string));
    State::Present { commit }
}

/// Runs git with `args` (in `dir` when given); its progress goes to our stderr.
fn git(dir: Option<&Path>, args: &[&str]) -> Result<()> {
    let mut cmd = Command::new("git");
    if let Some(d) = dir {
        cmd.arg("-C").arg(d);
    }
    let status = cmd
        .args(args)
        .stdout(Stdio::null())
        .status()
        .context("cannot run git (is it installed?)")?;
    if !status.success() {
        bail!("git {} failed ({status})", args.join(" "));
    }
    Ok(())
}

/// git's one-line answer to `args` in `dir`.
fn git_output(dir: &Path, args: &[&str]) -> Result<String> {
    let out = Command::new("git")
        .arg("-C")
        .arg(dir)
        .args(args)
        .stderr(Stdio::null())
        .output()
        .context("cannot run git (is it installed?)")?;
    if !out.status.success() {
        bail!("git {} in {} failed", args.join(" "), dir.display());
    }
    Ok(String::from_utf8_lossy(&out.stdout).trim().to_string())
}

/// The source repository of `set` at `url`, in `cache`, checked out with (at least) the files
/// `steps` read; an existing clone of the same URL is reused unless `fresh`.
fn source_checkout(url: &str, cache: &Path, steps: &[Step], fresh: bool) -> Result<()> {
    let patterns: Vec<String> = steps.iter().map(|s| format!("/{}", s.source)).collect();
    let mut sparse = vec!["sparse-checkout", "set", "--no-cone"];
    sparse.extend(patterns.iter().map(String::as_str));
    let reusable = !fresh
        && cache.join(".git").is_dir()
        && git_output(cache, &["remote", "get-url", "origin"]).is_ok_and(|u| u == url);
    if reusable {
        eprintln!("  reusing the clone in {}", cache.display());
        return git(Some(cache), &sparse);
    }
    if cache.exists() {
        std::fs::remove_dir_all(cache)
            .with_context(|| format!("cannot remove the stale clone {}", cache.display()))?;
    }
    let partial = cache.with_extension("partial");
    if partial.exists() {
        std::fs::remove_dir_all(&partial)
            .with_context(|| format!("cannot remove {}", partial.display()))?;
    }
    if let Some(parent) = cache.parent() {
        std::fs::create_dir_all(parent)
            .with_context(|| format!("cannot create {}", parent.display()))?;
    }
    eprintln!("  cloning {url} (one commit, {} files)", patterns.len());
    let partial_str = partial
        .to_str()
        .ok_or_else(|| anyhow!("{}: not UTF-8", partial.display()))?;
    git(
        None,
        &[
            "clone",
            "--depth",
            "1",
            "--filter=blob:none",
            "--no-checkout",
            url,
            partial_str,
        ],
    )?;
    git(Some(&partial), &sparse)?;
    git(Some(&partial), &["checkout"])?;
    std::fs::rename(&partial, cache)
        .with_context(|| format!("cannot move {} to {}", partial.display(), cache.display()))?;
    Ok(())
}

/// The bytes of one source file, refusing a Git LFS pointer (the file itself is not in the
/// repository) with a message that says so.
fn read_source(checkout: &Path, step: &Step) -> Result<Vec<u8>> {
    let path = checkout.join(&step.source);
    let bytes = std::fs::read(&path).with_context(|| {
        format!(
            "{}: not in the source checkout (is it still published there?)",
            step.source
        )
    })?;
    if bytes.starts_with(LFS_POINTER) {
        bail!(
            "{}: the repository holds a Git LFS pointer, not the file; fetch it with git lfs",
            step.source
        );
    }
    Ok(bytes)
}

fn write(dir: &Path, name: &str, bytes: &[u8]) -> Result<()> {
    let path = dir.join(name);
    if let Some(parent) = path.parent() {
        std::fs::create_dir_all(parent)
            .with_context(|| format!("cannot create {}", parent.display()))?;
    }
    std::fs::write(&path, bytes).with_context(|| format!("cannot write {}", path.display()))
}

/// Makes every file of `set` in `out` from the checkout; returns the number of files written.
fn build(
    set: &'static DataSet,
    checkout: &Path,
    out: &Path,
    url: &str,
    commit: &str,
) -> Result<usize> {
    let steps = plan(set);
    let mut bar = Progress::new(set.name);
    let mut written = 0;
    for (k, step) in steps.iter().enumerate() {
        let bytes = read_source(checkout, step)?;
        match step.conversion {
            Conversion::Copy => write(out, &step.outputs[0], &bytes)?,
            Conversion::PyshoeMat => {
                let vars = mat::parse_mat(&bytes).with_context(|| step.source.clone())?;
                let files =
                    pyshoe_mat::convert_trial(&vars).with_context(|| step.source.clone())?;
                write(out, &step.outputs[0], files.csv.as_bytes())?;
                write(out, &step.outputs[1], files.json.as_bytes())?;
            }
        }
        written += step.outputs.len();
        bar.set(k + 1, steps.len());
    }
    bar.finish();
    write(
        out,
        PROVENANCE_FILE,
        provenance(set, url, commit).as_bytes(),
    )?;
    Ok(written + 1)
}

/// Fetches one set into `root`; `Ok(false)` when it was already there.
fn fetch_one(set: &'static DataSet, root: &Path, url: &str, force: bool) -> Result<bool> {
    let set_dir = root.join(set.name);
    let ours = set_dir.join(PROVENANCE_FILE).is_file();
    match state(set, &set_dir) {
        State::Present { commit } if !force => {
            match commit {
                Some(c) => eprintln!("{}: present (commit {c}), nothing to do", set.name),
                None => eprintln!(
                    "{}: present (no {PROVENANCE_FILE}: installed by hand), left as it is; --force replaces it",
                    set.name
                ),
            }
            return Ok(false);
        }
        State::Incomplete { absent, first } if !ours && !force => bail!(
            "{} exists without {PROVENANCE_FILE} and lacks {absent} file(s) (first {first}); move it away or pass --force to replace it",
            set_dir.display()
        ),
        _ => {}
    }
    eprintln!("{}: {}", set.name, set.description);
    let cache = root.join(".sources").join(set.name);
    let steps = plan(set);
    source_checkout(url, &cache, &steps, force)?;
    let commit = git_output(&cache, &["rev-parse", "HEAD"])?;
    let partial = root.join(format!(".{}.partial", set.name));
    if partial.exists() {
        std::fs::remove_dir_all(&partial)
            .with_context(|| format!("cannot remove {}", partial.display()))?;
    }
    let files = build(set, &cache, &partial, url, &commit)?;
    if set_dir.exists() {
        std::fs::remove_dir_all(&set_dir)
            .with_context(|| format!("cannot replace {}", set_dir.display()))?;
    }
    std::fs::rename(&partial, &set_dir)
        .with_context(|| format!("cannot move {} to {}", partial.display(), set_dir.display()))?;
    eprintln!(
        "{}: {files} files from {url} at commit {commit} in {}",
        set.name,
        set_dir.display()
    );
    Ok(true)
}

/// `rins data fetch`.
pub fn run_fetch(args: &DataFetchArgs) -> Result<ExitCode> {
    let sets = selected(&args.sets)?;
    let overrides = source_overrides(&args.sources)?;
    let root = recordings_dir(args.dir.as_deref());
    std::fs::create_dir_all(&root).with_context(|| format!("cannot create {}", root.display()))?;
    let mut failed = Vec::new();
    let (mut fetched, mut present) = (0, 0);
    for set in sets {
        let url = overrides
            .iter()
            .rev()
            .find(|(name, _)| *name == set.name)
            .map_or(set.url, |(_, u)| u.as_str());
        match fetch_one(set, &root, url, args.force) {
            Ok(true) => fetched += 1,
            Ok(false) => present += 1,
            Err(e) => {
                eprintln!("{}: failed: {e:#}", set.name);
                failed.push(set.name);
            }
        }
    }
    println!(
        "{fetched} fetched, {present} already present, {} failed{} in {}",
        failed.len(),
        if failed.is_empty() {
            String::new()
        } else {
            format!(" ({})", failed.join(", "))
        },
        root.display()
    );
    Ok(if failed.is_empty() {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    })
}

/// `rins data list`.
pub fn run_list(args: &DataListArgs) -> Result<ExitCode> {
    let root = recordings_dir(args.dir.as_deref());
    let mut rows = Vec::new();
    for set in &DATA_SETS {
        let dir = root.join(set.name);
        let st = state(set, &dir);
        let (status, detail) = match &st {
            State::Missing => ("missing", format!("rins data fetch {}", set.name)),
            State::Incomplete { absent, first } => (
                "incomplete",
                format!(
                    "{absent} file(s) absent (first {first}); rins data fetch --force {}",
                    set.name
                ),
            ),
            State::Present { commit: Some(c) } => ("present", format!("commit {c}")),
            State::Present { commit: None } => ("present", "installed by hand".to_string()),
        };
        rows.push((set, dir, status, detail));
    }
    if args.json {
        let sets: Vec<serde_json::Value> = rows
            .iter()
            .map(|(set, dir, status, detail)| {
                serde_json::json!({
                    "name": set.name,
                    "dir": dir.display().to_string(),
                    "status": status,
                    "detail": detail,
                    "source": set.url,
                })
            })
            .collect();
        println!(
            "{}",
            serde_json::json!({ "dir": root.display().to_string(), "sets": sets })
        );
    } else {
        println!("recordings directory: {}", root.display());
        for (set, _, status, detail) in &rows {
            println!("  {:<16} {:<10} {detail}", set.name, status);
        }
    }
    Ok(ExitCode::SUCCESS)
}
