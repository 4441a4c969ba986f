//! Output folders and files: nothing half-written, nothing clobbered by accident.

use czid_core::{CzError, Result};
use std::path::{Path, PathBuf};

pub use czid_optimizers::checkpoint::write_atomic;

/// An output folder that was checked before anything was written to it.
#[derive(Clone, Debug)]
pub struct OutputDir {
    path: PathBuf,
}

impl OutputDir {
    /// Creates `path`. An existing non-empty folder is an error unless `force` is set (then its
    /// files are overwritten one by one, each atomically) or `resume` is set (a run continues in it).
    pub fn create(path: &Path, force: bool, resume: bool) -> Result<Self> {
        let shown = path.display().to_string();
        let io = |e: std::io::Error| CzError::Io { path: shown.clone(), message: e.to_string() };
        if path.exists() {
            if !path.is_dir() {
                return Err(CzError::Io { path: shown, message: "exists and is not a folder".into() });
            }
            let occupied = std::fs::read_dir(path).map_err(io)?.next().is_some();
            if occupied && !force && !resume {
                return Err(CzError::Io {
                    path: shown,
                    message: "the output folder already holds results; pass --force to overwrite them, \
                              --resume to continue an interrupted run, or choose another --out"
                        .into(),
                });
            }
        } else {
            std::fs::create_dir_all(path).map_err(io)?;
        }
        Ok(OutputDir { path: path.to_path_buf() })
    }

    /// The folder.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// A file inside the folder.
    pub fn file(&self, name: &str) -> PathBuf {
        self.path.join(name)
    }

    /// Writes a text file atomically.
    pub fn write(&self, name: &str, text: &str) -> Result<PathBuf> {
        let p = self.file(name);
        write_atomic(&p, text.as_bytes())?;
        Ok(p)
    }

    /// Writes columns as a CSV file atomically; `header` names them (with units).
    pub fn write_csv(&self, name: &str, header: &[String], columns: &[Vec<f64>]) -> Result<PathBuf> {
        let rows = columns.iter().map(Vec::len).max().unwrap_or(0);
        let mut text = header.join(",");
        text.push('\n');
        for i in 0..rows {
            let row: Vec<String> = columns.iter().map(|c| c.get(i).map_or(String::new(), |v| format!("{v}"))).collect();
            text.push_str(&row.join(","));
            text.push('\n');
        }
        self.write(name, &text)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refuses_to_clobber_without_force() {
        let dir = std::env::temp_dir().join(format!("czid-out-{}", std::process::id()));
        let out = OutputDir::create(&dir, false, false).unwrap();
        out.write("a.txt", "x").unwrap();
        let e = OutputDir::create(&dir, false, false).unwrap_err().to_string();
        assert!(e.contains("--force"), "{e}");
        assert!(OutputDir::create(&dir, true, false).is_ok());
        let csv = out.write_csv("c.csv", &["a (mm)".into(), "b (N)".into()], &[vec![1.0, 2.0], vec![3.0]]).unwrap();
        assert_eq!(std::fs::read_to_string(csv).unwrap(), "a (mm),b (N)\n1,3\n2,\n");
        std::fs::remove_dir_all(&dir).ok();
    }
}
