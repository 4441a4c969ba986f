//! Every bundled example file reads: problem files (`[[experiment]]`) with their data, and model
//! files (`[law]` and `[model]`, what `czid simulate` and `czid synthesize` run) with their
//! checks. A key renamed or a data file moved in the library then fails here, not in a user's
//! first command.

use std::path::{Path, PathBuf};

use czid_problems::problem_file::LoadedProblem;
use czid_problems::synthetic::TruthFile;

fn toml_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            toml_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "toml") {
            out.push(path);
        }
    }
}

#[test]
fn every_bundled_example_file_reads() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples");
    let mut files = Vec::new();
    toml_files(&root, &mut files);
    files.sort();
    // The problem and model files of the README's table and the book (28 when this was written).
    assert!(files.len() >= 28, "only {} example files found under {}", files.len(), root.display());
    let mut failures = Vec::new();
    for path in &files {
        let table: toml::Table = std::fs::read_to_string(path).unwrap().parse().unwrap();
        // As `czid simulate` tells them apart.
        let read = if table.contains_key("model") && !table.contains_key("experiment") {
            TruthFile::read(path).map(|_| ())
        } else {
            LoadedProblem::read(path).map(|_| ())
        };
        if let Err(e) = read {
            failures.push(format!("{}: {e}", path.display()));
        }
    }
    assert!(failures.is_empty(), "example files that do not read:\n{}", failures.join("\n"));
}
