//! The data directory (`--data DIR`): the only files the server reads.
//!
//! A path from the page is relative to it, names no `..`, root or prefix,
//! and still lies inside it once symbolic links are resolved; nothing is
//! ever written. Without `--data` no file can be read.

use std::path::{Component, Path, PathBuf};

/// What a data file is, by its extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum DataKind {
    /// A measured table (MERL `.binary`, RGL `.bsdf`).
    Measured,
    /// An environment map (`.hdr`, `.pic`, `.exr`).
    Envmap,
}

impl DataKind {
    fn of(path: &Path) -> Option<Self> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "binary" | "bsdf" => Some(DataKind::Measured),
            "hdr" | "pic" | "exr" => Some(DataKind::Envmap),
            _ => None,
        }
    }
}

/// One file the page may ask for.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct DataFile {
    /// Relative to the data directory, `/`-separated.
    pub path: String,
    pub kind: DataKind,
}

/// The most files listed (a directory of many files lists the first ones
/// in name order).
const MAX_LISTED: usize = 1000;
/// How deep the listing goes below the data directory.
const MAX_DEPTH: usize = 4;

/// The data directory, canonical, or none.
#[derive(Debug, Clone, Default)]
pub struct DataDir {
    root: Option<PathBuf>,
}

impl DataDir {
    /// `dir` must exist and be a directory.
    pub fn new(dir: Option<&Path>) -> Result<Self, String> {
        let Some(dir) = dir else {
            return Ok(DataDir { root: None });
        };
        let root = dir
            .canonicalize()
            .map_err(|e| format!("--data {}: {e}", dir.display()))?;
        if !root.is_dir() {
            return Err(format!("--data {}: not a directory", dir.display()));
        }
        Ok(DataDir { root: Some(root) })
    }

    /// The file `rel` names inside the data directory, or why not.
    pub fn resolve(&self, rel: &str) -> Result<PathBuf, String> {
        let Some(root) = &self.root else {
            return Err(format!(
                "`{rel}`: no data directory was given (start lobe explore with --data DIR to read files)"
            ));
        };
        if rel.is_empty() || rel.len() > 1024 || rel.contains('\0') {
            return Err("a data file path must be 1 to 1024 characters".into());
        }
        let p = Path::new(rel);
        if p.is_absolute()
            || p.components()
                .any(|c| !matches!(c, Component::Normal(_) | Component::CurDir))
        {
            return Err(format!(
                "`{rel}`: a data file is named relative to the data directory, without `..`"
            ));
        }
        let full = root
            .join(p)
            .canonicalize()
            .map_err(|_| format!("`{rel}`: no such file in the data directory"))?;
        if !full.starts_with(root) {
            return Err(format!(
                "`{rel}`: leads out of the data directory (a symbolic link)"
            ));
        }
        if !full.is_file() {
            return Err(format!("`{rel}`: not a file"));
        }
        Ok(full)
    }

    /// The measured tables and environment maps in the data directory (by
    /// extension, in name order, at most [`MAX_LISTED`], [`MAX_DEPTH`]
    /// levels down, links leading out of it left out).
    #[must_use]
    pub fn list(&self) -> Vec<DataFile> {
        let mut out = Vec::new();
        if let Some(root) = &self.root {
            walk(root, root, 0, &mut out);
        }
        out
    }
}

fn walk(root: &Path, dir: &Path, depth: usize, out: &mut Vec<DataFile>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let mut paths: Vec<PathBuf> = entries.filter_map(|e| e.ok().map(|e| e.path())).collect();
    paths.sort();
    for p in paths {
        if out.len() >= MAX_LISTED {
            return;
        }
        let Ok(canon) = p.canonicalize() else {
            continue;
        };
        if !canon.starts_with(root) {
            continue;
        }
        if canon.is_dir() {
            if depth + 1 < MAX_DEPTH && canon != *root {
                walk(root, &p, depth + 1, out);
            }
            continue;
        }
        let (Some(kind), Ok(rel)) = (DataKind::of(&p), p.strip_prefix(root)) else {
            continue;
        };
        let parts: Vec<String> = rel
            .components()
            .map(|c| c.as_os_str().to_string_lossy().into_owned())
            .collect();
        out.push(DataFile {
            path: parts.join("/"),
            kind,
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("lobe-explore-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn only_files_inside_the_directory_resolve() {
        let d = scratch("sandbox");
        let data = d.join("data");
        std::fs::create_dir_all(data.join("merl")).unwrap();
        std::fs::write(data.join("merl/a.binary"), b"x").unwrap();
        std::fs::write(d.join("secret.binary"), b"s").unwrap();
        #[cfg(unix)]
        std::os::unix::fs::symlink(d.join("secret.binary"), data.join("out.binary")).unwrap();
        let dd = DataDir::new(Some(&data)).unwrap();
        assert!(dd.resolve("merl/a.binary").is_ok());
        assert!(dd.resolve("./merl/a.binary").is_ok());
        for bad in [
            "../secret.binary",
            "merl/../../secret.binary",
            "/etc/passwd",
            "",
            "missing.binary",
            "merl",
        ] {
            let e = dd.resolve(bad).unwrap_err();
            assert!(!e.is_empty(), "{bad}");
        }
        #[cfg(unix)]
        assert!(
            dd.resolve("out.binary")
                .unwrap_err()
                .contains("out of the data directory")
        );
        let listed: Vec<String> = dd.list().into_iter().map(|f| f.path).collect();
        assert_eq!(listed, ["merl/a.binary"]);
        let none = DataDir::new(None).unwrap();
        assert!(
            none.resolve("merl/a.binary")
                .unwrap_err()
                .contains("--data")
        );
        assert!(none.list().is_empty());
    }
}
