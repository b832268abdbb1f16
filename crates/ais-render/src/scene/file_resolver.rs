//! Where a scene's relative file names point, by Mitsuba's rules: the folders given by
//! `<path value="…"/>` (the last one first, each relative to the scene file's folder), then
//! the scene file's own folder. The first folder that holds the file wins; if none does,
//! the name resolves against the scene's folder, so that the error names that path.

use std::path::{Path, PathBuf};

/// The folders a scene's relative file names are searched in.
#[derive(Clone, Debug, PartialEq)]
pub struct FileResolver {
    /// Searched first to last; the scene's folder is last.
    folders: Vec<PathBuf>,
}

impl FileResolver {
    /// The resolver of the scene file `scene`, with its `<path>` values in file order.
    pub fn new(scene: &Path, paths: &[String]) -> Self {
        let own = scene.parent().unwrap_or(Path::new(".")).to_path_buf();
        let mut folders: Vec<PathBuf> = paths.iter().rev().map(|p| own.join(p)).collect();
        folders.push(own);
        FileResolver { folders }
    }

    /// The file `name` names: itself if absolute, else in the first folder that holds it,
    /// else in the scene's folder.
    pub fn resolve(&self, name: &str) -> PathBuf {
        let name = Path::new(name);
        if name.is_absolute() {
            return name.to_path_buf();
        }
        self.folders
            .iter()
            .map(|folder| folder.join(name))
            .find(|candidate| candidate.exists())
            .unwrap_or_else(|| self.scene_folder().join(name))
    }

    /// The scene file's folder.
    pub fn scene_folder(&self) -> &Path {
        self.folders
            .last()
            .expect("the scene's folder is always there")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn path_elements_are_searched_before_the_scene_folder_last_first() {
        let root = std::env::temp_dir().join(format!("ais-resolver-{}", std::process::id()));
        for folder in ["scene", "scene/meshes", "scene/more"] {
            std::fs::create_dir_all(root.join(folder)).unwrap();
        }
        std::fs::write(root.join("scene/meshes/a.obj"), "").unwrap();
        std::fs::write(root.join("scene/more/a.obj"), "").unwrap();
        std::fs::write(root.join("scene/b.obj"), "").unwrap();
        let files = FileResolver::new(
            &root.join("scene/test.xml"),
            &["meshes".into(), "more".into()],
        );
        assert_eq!(files.resolve("a.obj"), root.join("scene/more/a.obj"));
        assert_eq!(files.resolve("b.obj"), root.join("scene/b.obj"));
        assert_eq!(files.resolve("missing.obj"), root.join("scene/missing.obj"));
        assert_eq!(files.resolve("/abs/c.obj"), PathBuf::from("/abs/c.obj"));
        std::fs::remove_dir_all(root).unwrap();
    }
}
