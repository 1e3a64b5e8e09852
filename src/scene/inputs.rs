//! The files a scene's load reads beside its own (textures, sky maps, meshes, glTF files with
//! their buffers and images), as a render must not write over them: `-o` naming the texture a
//! scene paints with would replace it with the render.

use std::cell::RefCell;
use std::path::{Path, PathBuf};

thread_local! {
    /// The files read by the load under way on this thread (a load reads its files on the
    /// thread that loads it); None outside one.
    static READ: RefCell<Option<Vec<PathBuf>>> = const { RefCell::new(None) };
}

/// Record that the load under way reads `path`.
pub(super) fn note(path: &Path) {
    READ.with_borrow_mut(|read| {
        if let Some(read) = read {
            if !read.iter().any(|p| p == path) {
                read.push(path.to_path_buf());
            }
        }
    });
}

/// `load`'s result, and the files it read (a load within it counts in both).
pub(super) fn recorded<T>(load: impl FnOnce() -> T) -> (T, Vec<PathBuf>) {
    let outer = READ.with_borrow_mut(|read| read.replace(Vec::new()));
    let result = load();
    let inner = READ.with_borrow_mut(|read| std::mem::replace(read, outer).unwrap_or_default());
    for path in &inner {
        note(path);
    }
    (result, inner)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_load_records_what_it_reads_and_nothing_outside_one() {
        note(Path::new("outside.png"));
        let ((), outer) = recorded(|| {
            note(Path::new("a.png"));
            let ((), inner) = recorded(|| note(Path::new("b.obj")));
            assert_eq!(inner, [PathBuf::from("b.obj")]);
            note(Path::new("a.png"));
        });
        assert_eq!(outer, [PathBuf::from("a.png"), PathBuf::from("b.obj")]);
        let ((), none) = recorded(|| ());
        assert!(none.is_empty());
    }
}
