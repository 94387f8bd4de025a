//! Atomic file writes: the content goes to a temporary file in the target's directory,
//! which is flushed to disk and then renamed over the target.
//!
//! A rename within one directory (one file system) replaces the target in one step, so a
//! reader sees the old file or the new one, whole; a run killed while writing leaves the
//! old file and at most a hidden temporary file. Every write uses its own temporary name
//! (`.tmp.<process id>.<counter>.<file name>`), so two threads or processes writing the
//! same target never mix their bytes: the last rename wins. The temporary name keeps the
//! target's extension, for writers that pick the format from it (image encoders).

use std::ffi::OsString;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use crate::error::VtkError;

/// Size of the write buffer of [`write_atomic_with`].
const BUFFER: usize = 1 << 20;

/// A fresh temporary path next to `path`.
fn temp_path(path: &Path) -> Result<PathBuf, VtkError> {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let name = path.file_name().ok_or_else(|| VtkError::Io {
        path: path.to_path_buf(),
        source: std::io::Error::new(std::io::ErrorKind::InvalidInput, "not a file path"),
    })?;
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let mut tmp = OsString::from(format!(".tmp.{}.{n}.", std::process::id()));
    tmp.push(name);
    Ok(path.with_file_name(tmp))
}

/// Let `make` create the file at a temporary path next to `path`, then rename it over
/// `path`. On any failure the temporary file is removed and the error names `path`.
///
/// This is the form for writers that open the file themselves (an image library given a
/// path); the temporary path has the extension of `path`.
pub fn write_atomic_via(
    path: &Path,
    make: impl FnOnce(&Path) -> std::io::Result<()>,
) -> Result<(), VtkError> {
    let tmp = temp_path(path)?;
    let result = make(&tmp).and_then(|()| std::fs::rename(&tmp, path));
    result.map_err(|source| {
        let _ = std::fs::remove_file(&tmp);
        VtkError::Io {
            path: path.to_path_buf(),
            source,
        }
    })
}

/// Write the file `path` atomically with the bytes that `body` writes (through a 1 MiB
/// buffer; the file is synced to disk before the rename). Nothing is held in memory but
/// the buffer.
pub fn write_atomic_with(
    path: &Path,
    body: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<(), VtkError> {
    write_atomic_via(path, |tmp| {
        let mut w = BufWriter::with_capacity(BUFFER, File::create(tmp)?);
        body(&mut w)?;
        let f = w.into_inner().map_err(|e| e.into_error())?;
        f.sync_all()
    })
}

/// Write `bytes` to `path` atomically (see the module docs). The directory must exist.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), VtkError> {
    write_atomic_via(path, |tmp| {
        let mut f = File::create(tmp)?;
        f.write_all(bytes)?;
        f.sync_all()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(name: &str) -> PathBuf {
        let d =
            std::env::temp_dir().join(format!("porofrac_vtk_atomic_{name}_{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    fn names(d: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn replaces_whole_and_leaves_no_temporary() {
        let d = dir("whole");
        let p = d.join("a.txt");
        write_atomic(&p, &[b'x'; 10_000]).unwrap();
        write_atomic(&p, b"short").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"short");
        write_atomic_with(&p, |w: &mut dyn Write| w.write_all(b"streamed")).unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"streamed");
        assert_eq!(names(&d), ["a.txt"]);
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn failure_keeps_old_file_and_removes_temporary() {
        let d = dir("fail");
        let p = d.join("b.vtu");
        write_atomic(&p, b"old").unwrap();
        let e = write_atomic_with(&p, |w: &mut dyn Write| {
            w.write_all(b"half")?;
            Err(std::io::Error::other("disk full"))
        })
        .unwrap_err();
        assert_eq!(e.to_string(), format!("{}: disk full", p.display()));
        assert_eq!(std::fs::read(&p).unwrap(), b"old");
        assert_eq!(names(&d), ["b.vtu"]);
        // A missing directory is an error naming the target.
        let q = d.join("missing").join("c.vtu");
        let e = write_atomic(&q, b"x").unwrap_err();
        assert!(matches!(&e, VtkError::Io { path, .. } if *path == q), "{e}");
        // Not a file path.
        assert!(write_atomic(Path::new("/"), b"x").is_err());
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn temporary_keeps_extension_and_is_unique() {
        let p = Path::new("/x/plot.png");
        let a = temp_path(p).unwrap();
        let b = temp_path(p).unwrap();
        assert_ne!(a, b);
        assert_eq!(a.extension().unwrap(), "png");
        assert_eq!(a.parent(), p.parent());
        assert!(
            a.file_name()
                .unwrap()
                .to_string_lossy()
                .starts_with(".tmp.")
        );
    }

    #[test]
    fn concurrent_writers_never_mix() {
        let d = dir("threads");
        let p = d.join("c.bin");
        std::thread::scope(|s| {
            for k in 0..4u8 {
                let p = &p;
                s.spawn(move || {
                    for _ in 0..20 {
                        write_atomic(p, &vec![k; 50_000 + k as usize]).unwrap();
                    }
                });
            }
        });
        let bytes = std::fs::read(&p).unwrap();
        let k = bytes[0];
        assert_eq!(bytes.len(), 50_000 + k as usize);
        assert!(bytes.iter().all(|&b| b == k));
        assert_eq!(names(&d), ["c.bin"]);
        std::fs::remove_dir_all(&d).unwrap();
    }
}
