//! Where a scene's files come from: the file system, or files held in memory (those a user
//! dropped on the web page), so that one loader serves both. A scene file names the others
//! (glTF buffers and images, OBJ's MTL libraries and their textures) by paths relative to
//! itself; in memory they are found by that relative path, else by their file name alone
//! (dropped files arrive without folders).

use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// The files a loader reads.
#[derive(Clone, Copy, Debug)]
pub enum Files<'a> {
    /// The file system.
    Disk,
    /// Files in memory by name; nothing else exists.
    Memory(&'a MemoryFiles),
}

/// Files held in memory, by their names ('/'-separated relative paths or bare file names).
#[derive(Clone, Debug, Default)]
pub struct MemoryFiles {
    files: HashMap<String, Vec<u8>>,
}

impl MemoryFiles {
    pub fn new() -> MemoryFiles {
        MemoryFiles::default()
    }

    /// Adds (or replaces) the file `name`.
    pub fn insert(&mut self, name: &str, bytes: Vec<u8>) {
        self.files.insert(normalise(name), bytes);
    }

    /// The file at `path`: by its whole relative path, else by its file name.
    pub fn get(&self, path: &Path) -> Option<&[u8]> {
        self.key_of(path).and_then(|k| self.files.get(k)).map(Vec::as_slice)
    }

    /// The name under which [`MemoryFiles::get`] finds the file at `path`.
    fn key_of(&self, path: &Path) -> Option<&str> {
        let whole = normalise(&path.to_string_lossy());
        if let Some((k, _)) = self.files.get_key_value(&whole) {
            return Some(k);
        }
        let name = whole.rsplit('/').next()?;
        match self.files.get_key_value(name) {
            Some((k, _)) => Some(k),
            None => self.files.keys().find(|k| k.rsplit('/').next() == Some(name)).map(String::as_str),
        }
    }

    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.files.keys().map(String::as_str)
    }
}

/// `a\b/./c` → `a/b/c`, without a leading `./` or `/`.
fn normalise(name: &str) -> String {
    name.replace('\\', "/").split('/').filter(|p| !p.is_empty() && *p != ".").collect::<Vec<_>>().join("/")
}

impl Files<'_> {
    /// Whether `path` names something that is not a regular file (a device or a pipe, such
    /// as `/dev/zero`, would be read forever).
    pub fn is_special(&self, path: &Path) -> bool {
        match self {
            Files::Disk => path.exists() && !path.is_file(),
            Files::Memory(_) => false,
        }
    }

    /// `None` where `path` is a regular file, else what it is instead: "no such file" or
    /// "is not a file".
    pub fn missing(&self, path: &Path) -> Option<&'static str> {
        match self {
            Files::Disk if path.is_file() => None,
            Files::Disk if path.exists() => Some("is not a file"),
            Files::Memory(m) if m.get(path).is_some() => None,
            _ => Some("no such file"),
        }
    }

    /// The file's size in bytes, where it is a file.
    pub fn size(&self, path: &Path) -> Option<u64> {
        match self {
            Files::Disk => std::fs::metadata(path).ok().filter(|m| m.is_file()).map(|m| m.len()),
            Files::Memory(m) => m.get(path).map(|b| b.len() as u64),
        }
    }

    /// The file `path` names, however it is spelled (`a/../b.png`, `./b.png`, a link): the
    /// key that caches of files read once use. On disk the canonical path (the path as given
    /// where it cannot be resolved); in memory the name of the file it finds.
    pub fn canonical(&self, path: &Path) -> PathBuf {
        match self {
            Files::Disk => std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf()),
            Files::Memory(m) => m.key_of(path).map_or_else(|| path.to_path_buf(), PathBuf::from),
        }
    }

    /// The file's bytes.
    pub fn read(&self, path: &Path) -> std::io::Result<Vec<u8>> {
        match self {
            Files::Disk => std::fs::read(path),
            Files::Memory(m) => m.get(path).map(<[u8]>::to_vec).ok_or_else(|| {
                std::io::Error::new(
                    std::io::ErrorKind::NotFound,
                    "it is not among the files given; drop or pick it together with the scene",
                )
            }),
        }
    }

    /// The file as UTF-8 text.
    pub fn read_to_string(&self, path: &Path) -> std::io::Result<String> {
        String::from_utf8(self.read(path)?)
            .map_err(|_| std::io::Error::new(std::io::ErrorKind::InvalidData, "stream did not contain valid UTF-8"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn memory_files_are_found_by_relative_path_or_by_name() {
        let mut m = MemoryFiles::new();
        m.insert("textures\\wood.png", vec![1]);
        m.insert("scene.bin", vec![2]);
        assert_eq!(m.get(Path::new("textures/wood.png")), Some(&[1u8][..]));
        assert_eq!(m.get(Path::new("./models/scene.bin")), Some(&[2u8][..]));
        assert_eq!(m.get(Path::new("other/wood.png")), Some(&[1u8][..]));
        assert_eq!(m.get(Path::new("stone.png")), None);
        let files = Files::Memory(&m);
        assert_eq!(files.missing(Path::new("stone.png")), Some("no such file"));
        assert!(files.read(Path::new("stone.png")).unwrap_err().to_string().contains("not among the files given"));
        // Every spelling of one file is one file.
        for spelling in ["textures/wood.png", "./textures/../textures/wood.png", "a\\..\\wood.png"] {
            assert_eq!(files.canonical(Path::new(spelling)), PathBuf::from("textures/wood.png"), "{spelling}");
        }
        assert_eq!(files.size(Path::new("scene.bin")), Some(1));
    }
}
