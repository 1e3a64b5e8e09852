//! Writing a file so that no file is lost and none is left half-written: the bytes go to a
//! hidden file beside the target (`.NAME.partial-MACHINE-PID`), are synced to the disk, and are renamed
//! over the target only when complete, with the target's permissions. A symbolic link is
//! written through (the link stays, its target is replaced); a read-only target or a directory
//! is refused, and so is a device, FIFO or socket. Partial files of this machine's runs that
//! died (killed, or the machine stopped) are removed by the next write into the same folder; another
//! node's on a shared file system, or another container's, are left to their writers
//! ([`partial_path`]); the command line removes its own on Ctrl-C and SIGTERM
//! ([`remove_partial_files`]).

use crate::{Cause, Error};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// Partial files being written now, for [`remove_partial_files`].
static PARTIAL: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Remove the partial files this process is writing (for a signal handler: the process is
/// about to end).
pub(crate) fn remove_partial_files() {
    let files = PARTIAL.lock().map(|f| f.clone()).unwrap_or_default();
    for f in files {
        let _ = std::fs::remove_file(f);
    }
}

/// Write `path` through `write` (which writes the whole file at the path it is given).
pub(crate) fn write_whole(
    path: &Path,
    write: impl FnOnce(&Path) -> Result<(), Cause>,
) -> crate::Result<()> {
    let refuse = |why: String| {
        Error::image(
            path,
            format!("cannot write `{}`: {why}", path.display()),
            None,
        )
    };
    let target = through_links(path).map_err(|e| refuse(e.to_string()))?;
    let existing = std::fs::metadata(&target).ok();
    if let Some(m) = &existing {
        if m.is_dir() {
            return Err(refuse("it is a directory".into()));
        }
        // A device, FIFO or socket (`-o /dev/null`, or a link to one) would be replaced by a
        // regular file: refused, left as it is.
        if !m.is_file() {
            return Err(refuse(format!(
                "it is not a regular file ({}); it was left as it is",
                kind_of(m)
            )));
        }
        if m.permissions().readonly() {
            return Err(refuse("the file is read-only; it was left as it is".into()));
        }
    }
    remove_stale_partials(&target);
    let tmp = partial_name(&target, std::process::id());
    if let Ok(mut p) = PARTIAL.lock() {
        p.push(tmp.clone());
    }
    let result = write(&tmp).and_then(|_| {
        if let Some(m) = &existing {
            std::fs::set_permissions(&tmp, m.permissions()).map_err(cause)?;
        }
        std::fs::File::open(&tmp)
            .and_then(|f| f.sync_all())
            .map_err(cause)?;
        std::fs::rename(&tmp, &target).map_err(cause)?;
        // The rename itself is on the disk once the directory is.
        if let Some(dir) = target.parent().filter(|d| !d.as_os_str().is_empty()) {
            let _ = std::fs::File::open(dir).and_then(|d| d.sync_all());
        }
        Ok(())
    });
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    if let Ok(mut p) = PARTIAL.lock() {
        p.retain(|f| f != &tmp);
    }
    result.map_err(|e| {
        let message = format!("cannot write `{}`: {e}", path.display());
        Error::image(path, message, Some(e))
    })
}

/// Refuse `path` where it is a symbolic link: one of several outputs of a run (a film's frame,
/// a farm's tile) is written to a file of its own, never through a link, which could lead to
/// another output of the same run (`frame-04.png -> frame-00.png` would overwrite frame 0).
/// `what` says which output it is. A still's `-o` may be a link to a regular file (as shell
/// redirection writes through one); [`write_whole`] follows it.
pub(crate) fn refuse_link(path: &Path, what: &str) -> crate::Result<()> {
    match std::fs::symlink_metadata(path) {
        Ok(m) if m.file_type().is_symlink() => {
            let to = std::fs::read_link(path)
                .map(|t| t.display().to_string())
                .unwrap_or_else(|_| "somewhere unreadable".into());
            Err(Error::image(path, format!(
                "{what} `{}` is a symbolic link to `{to}`: each of a run's outputs is written to a file of its own, not through a link (it could lead to another of them); remove the link or name another file",
                path.display()
            ), None))
        }
        _ => Ok(()),
    }
}

/// The file a path names, following symbolic links (relative ones from the link's directory).
fn through_links(path: &Path) -> std::io::Result<PathBuf> {
    let mut p = path.to_path_buf();
    for _ in 0..40 {
        match std::fs::symlink_metadata(&p) {
            Ok(m) if m.file_type().is_symlink() => {
                let to = std::fs::read_link(&p)?;
                p = match p.parent() {
                    Some(dir) if to.is_relative() => dir.join(to),
                    _ => to,
                };
            }
            _ => return Ok(p),
        }
    }
    Err(std::io::Error::other("too many levels of symbolic links"))
}

/// What a file that is not a regular one is, in words.
pub(crate) fn kind_of(m: &std::fs::Metadata) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        let t = m.file_type();
        if t.is_char_device() {
            return "a character device";
        }
        if t.is_block_device() {
            return "a block device";
        }
        if t.is_fifo() {
            return "a FIFO";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    let _ = m;
    "a special file"
}

/// The partial file process `pid` of this machine writes `target` through:
/// `.NAME.partial-MACHINE-PID`, MACHINE naming the host, its boot and the PID namespace, so
/// that a run that finds it can tell whether its writer is a process it can see (and whether
/// that one still runs) or one on another node of a shared file system, or in another
/// container, which it must leave alone.
pub fn partial_path(target: &Path, pid: u32) -> PathBuf {
    let name = target
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    target.with_file_name(format!(".{name}.partial-{}-{pid}", machine()))
}

fn partial_name(target: &Path, pid: u32) -> PathBuf {
    partial_path(target, pid)
}

/// This machine as partial files name it: the host name, the first 8 digits of the boot id and
/// the PID namespace's number (Linux; elsewhere the host name alone), in letters, digits, `.`
/// and `_`.
fn machine() -> String {
    static MACHINE: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    MACHINE
        .get_or_init(|| {
            let read = |p: &str| std::fs::read_to_string(p).unwrap_or_default();
            let host = read("/proc/sys/kernel/hostname");
            let host = if host.trim().is_empty() {
                std::env::var("HOSTNAME").unwrap_or_else(|_| "host".into())
            } else {
                host
            };
            let boot: String = read("/proc/sys/kernel/random/boot_id")
                .chars()
                .filter(char::is_ascii_hexdigit)
                .take(8)
                .collect();
            let ns = std::fs::read_link("/proc/self/ns/pid")
                .map(|l| {
                    l.to_string_lossy()
                        .chars()
                        .filter(char::is_ascii_digit)
                        .collect::<String>()
                })
                .unwrap_or_default();
            [host.trim(), &boot, &ns]
                .iter()
                .filter(|p| !p.is_empty())
                .map(|p| {
                    p.chars()
                        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
                        .collect::<String>()
                })
                .collect::<Vec<_>>()
                .join(".")
        })
        .clone()
}

/// Remove the partial files in `target`'s folder, of any name, left by processes of this
/// machine that no longer run (Linux: no /proc/PID): a render killed outright leaves its file
/// to the next render into the folder, not only to the next of the same name (a film's
/// frames each have their own). Another machine's, another container's, or where it cannot
/// tell, it leaves.
fn remove_stale_partials(target: &Path) {
    let Some(dir) = target.parent() else {
        return;
    };
    let dir = if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    };
    if !Path::new("/proc/self").exists() {
        return;
    }
    let marker = format!(".partial-{}-", machine());
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let file = e.file_name().to_string_lossy().into_owned();
        let Some(pid) = file
            .strip_prefix('.')
            .and_then(|f| f.rsplit_once(&marker))
            .filter(|(name, _)| !name.is_empty())
            .and_then(|(_, pid)| pid.parse::<u32>().ok())
        else {
            continue;
        };
        if !Path::new(&format!("/proc/{pid}")).exists() {
            let _ = std::fs::remove_file(e.path());
        }
    }
}

/// An encoder's or the file system's error as a shared cause.
pub(crate) fn cause(e: impl std::error::Error + Send + Sync + 'static) -> Cause {
    std::sync::Arc::new(e)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(name: &str) -> PathBuf {
        let d =
            std::env::temp_dir().join(format!("rest-embree-file-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    fn bytes(text: &'static str) -> impl FnOnce(&Path) -> Result<(), Cause> {
        move |p| std::fs::write(p, text).map_err(cause)
    }

    #[test]
    fn a_failed_write_leaves_the_old_file_and_no_partial() {
        let d = dir("fail");
        let target = d.join("out.png");
        std::fs::write(&target, "old").unwrap();
        let failing = |p: &Path| {
            std::fs::write(p, "half").unwrap();
            Err(cause(std::io::Error::other("encoder failed")))
        };
        assert!(write_whole(&target, failing).is_err());
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "old");
        assert_eq!(
            std::fs::read_dir(&d).unwrap().count(),
            1,
            "no partial file left"
        );
    }

    #[cfg(unix)]
    #[test]
    fn links_are_written_through_and_modes_kept() {
        use std::os::unix::fs::PermissionsExt;
        let d = dir("link");
        let real = d.join("real.png");
        std::fs::write(&real, "old").unwrap();
        std::fs::set_permissions(&real, std::fs::Permissions::from_mode(0o640)).unwrap();
        let link = d.join("link.png");
        std::os::unix::fs::symlink("real.png", &link).unwrap();
        write_whole(&link, bytes("new")).unwrap();
        assert!(std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink());
        assert_eq!(std::fs::read_to_string(&real).unwrap(), "new");
        let mode = std::fs::metadata(&real).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, 0o640, "the target's mode is kept");
    }

    #[test]
    fn read_only_files_and_directories_are_refused() {
        let d = dir("ro");
        let target = d.join("keep.png");
        std::fs::write(&target, "keep").unwrap();
        let mut p = std::fs::metadata(&target).unwrap().permissions();
        p.set_readonly(true);
        std::fs::set_permissions(&target, p).unwrap();
        let e = write_whole(&target, bytes("new")).unwrap_err().to_string();
        assert!(e.contains("read-only"), "{e}");
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "keep");
        let e = write_whole(&d, bytes("new")).unwrap_err().to_string();
        assert!(e.contains("directory"), "{e}");
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn partial_files_of_dead_runs_are_removed() {
        let d = dir("stale");
        let target = d.join("out.exr");
        // No process has this id (above the kernel's pid_max of 2^22).
        let dead = partial_name(&target, 4_194_305);
        // Process 1 always runs: its partial file may be in the middle of being written.
        let live = partial_name(&target, 1);
        // Another file's, a frame of a film say, left by a run killed outright.
        let other = partial_name(&d.join("other.exr"), 4_194_305);
        let other_live = partial_name(&d.join("other.exr"), 1);
        // Another node's (or container's), or one of a version that did not name the
        // machine: its process cannot be seen from here.
        let elsewhere = d.join(".out.exr.partial-node7.0123abcd.4026531836-4194305");
        let unnamed = d.join(".out.exr.partial-4194305");
        for f in [&dead, &live, &other, &other_live, &elsewhere, &unnamed] {
            std::fs::write(f, "half").unwrap();
        }
        write_whole(&target, bytes("whole")).unwrap();
        assert!(!dead.exists(), "a dead run's partial file is removed");
        assert!(live.exists(), "a running process's partial file is left");
        assert!(
            !other.exists(),
            "another file's dead partial is removed too"
        );
        assert!(other_live.exists(), "another file's live partial is left");
        assert!(
            elsewhere.exists() && unnamed.exists(),
            "other machines' are left"
        );
        assert!(machine().contains('.'), "{}", machine());
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "whole");
    }
}
