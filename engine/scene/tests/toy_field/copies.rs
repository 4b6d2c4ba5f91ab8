//! Copies of this crate with edits, as a cargo workspace of their own in this build's
//! target folder. Kept between runs, so a run recompiles them incrementally; built
//! offline with this workspace's lock file and profiles, so their dependencies are the
//! ones this workspace built (but `dvr-volume`, outside the copies' workspace, and the
//! crates whose features `cargo test --workspace` unified otherwise: built once).

use std::fs::File;
use std::path::{Path, PathBuf};
use std::process::Command;

/// An edit of a copy: `text` goes in after `after`, which occurs once in `file`.
pub struct Edit {
    pub file: &'static str,
    pub after: &'static str,
    pub text: &'static str,
}

/// The copies' workspace.
pub struct Copies {
    dir: PathBuf,
    members: Vec<String>,
    // Held while the copies are written, built and run.
    _lock: File,
}

impl Copies {
    /// The workspace `name`, one per checkout (checkouts may share a target folder),
    /// locked so two runs of one checkout do not write the same copies.
    pub fn new(name: &str) -> Self {
        let key = {
            use std::hash::{Hash, Hasher};
            let mut h = std::hash::DefaultHasher::new();
            crate_dir().hash(&mut h);
            h.finish()
        };
        let dir = target_dir().join(format!("tmp/{name}-{key:016x}"));
        std::fs::create_dir_all(&dir).expect("mkdir");
        let lock = File::create(dir.with_extension("lock")).expect("lock file");
        lock.lock().expect("lock");
        // The crate includes files from `../../../assets`: the copies sit at
        // `engine/<folder>`, with the assets beside them.
        let assets = dir.join("assets");
        if !assets.exists() {
            std::os::unix::fs::symlink(workspace_dir().join("assets"), &assets)
                .expect("link the assets");
        }
        Self {
            dir,
            members: Vec::new(),
            _lock: lock,
        }
    }

    /// A copy of this crate's sources at `engine/<folder>` as package `package`, with
    /// `files` (path, text) added and `edits` applied.
    pub fn add(&mut self, folder: &str, package: &str, files: &[(&str, &str)], edits: &[&Edit]) {
        let member = format!("engine/{folder}");
        let dir = self.dir.join(&member);
        let _ = std::fs::remove_dir_all(&dir);
        copy_tree(&crate_dir().join("src"), &dir.join("src"));
        std::fs::write(dir.join("Cargo.toml"), manifest(package)).expect("write manifest");
        for (path, text) in files {
            std::fs::write(dir.join(path), text).expect("write file");
        }
        for edit in edits {
            let path = dir.join(edit.file);
            let text = std::fs::read_to_string(&path).expect("read copy");
            assert_eq!(
                text.matches(edit.after).count(),
                1,
                "{}: the edit goes after {:?}, which should occur once",
                edit.file,
                edit.after
            );
            let text = text.replacen(edit.after, &format!("{}{}", edit.after, edit.text), 1);
            std::fs::write(&path, text).expect("write copy");
        }
        self.members.push(member);
    }

    /// Builds every copy's unit tests (in parallel); `Err` holds cargo's output.
    pub fn build(&self) -> Result<(), String> {
        let workspace = read_toml(&workspace_dir().join("Cargo.toml"));
        let mut root = toml::Table::new();
        let members = toml::Value::from(self.members.clone());
        root.insert(
            "workspace".into(),
            toml::Table::from_iter([("members".into(), members), ("resolver".into(), "2".into())])
                .into(),
        );
        root.insert("profile".into(), workspace["profile"].clone());
        let root = toml::to_string(&root).expect("workspace manifest");
        std::fs::write(self.dir.join("Cargo.toml"), root).expect("write workspace");
        std::fs::copy(
            workspace_dir().join("Cargo.lock"),
            self.dir.join("Cargo.lock"),
        )
        .expect("copy Cargo.lock");
        match self.cargo(&["test", "--workspace", "--lib", "--no-run"]) {
            (true, _) => Ok(()),
            (false, log) => Err(log),
        }
    }

    /// Runs `package`'s unit tests whose names contain one of `filters`: whether they
    /// passed, and the tests' and cargo's output.
    pub fn test(&self, package: &str, filters: &[&str]) -> (bool, String) {
        let mut args = vec!["test", "-p", package, "--lib", "--"];
        args.extend_from_slice(filters);
        self.cargo(&args)
    }

    /// `cargo` in the workspace, offline, into this build's target folder.
    fn cargo(&self, args: &[&str]) -> (bool, String) {
        let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
        let out = Command::new(cargo)
            .arg("--offline")
            .args(args)
            .current_dir(&self.dir)
            .env("CARGO_TARGET_DIR", target_dir())
            .output()
            .expect("run cargo");
        let text = format!(
            "{}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
        (out.status.success(), text)
    }
}

/// How the test `test` ended in a test run's `output`: `Some("ok")`, `Some("FAILED")`,
/// or `None` where it did not run.
pub fn outcome<'a>(output: &'a str, test: &str) -> Option<&'a str> {
    let line = format!("test {test} ... ");
    output
        .lines()
        .find_map(|l| l.strip_prefix(line.as_str()))
        .map(str::trim)
}

/// This crate, its workspace and this build's target folder.
fn crate_dir() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn workspace_dir() -> PathBuf {
    crate_dir().join("../..")
}

fn target_dir() -> &'static Path {
    Path::new(env!("CARGO_TARGET_TMPDIR"))
        .parent()
        .expect("CARGO_TARGET_TMPDIR is <target>/tmp")
}

fn read_toml(path: &Path) -> toml::Table {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    text.parse()
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// This crate's manifest as a package `name` outside the workspace: what it inherits
/// from the workspace written out, path dependencies made absolute.
fn manifest(name: &str) -> String {
    let workspace = read_toml(&workspace_dir().join("Cargo.toml"));
    let inherited = |section: &str| workspace["workspace"][section].as_table().cloned();
    let (package_keys, dependencies) = (
        inherited("package").expect("[workspace.package]"),
        inherited("dependencies").expect("[workspace.dependencies]"),
    );
    let mut manifest = read_toml(&crate_dir().join("Cargo.toml"));
    manifest.remove("lib"); // the library takes the package's name
    let package = manifest["package"].as_table_mut().expect("[package]");
    for (key, value) in package.iter_mut() {
        if value.get("workspace").is_some() {
            *value = package_keys[key].clone();
        }
    }
    package.insert("name".into(), name.into());
    for section in ["dependencies", "dev-dependencies"] {
        let Some(deps) = manifest
            .get_mut(section)
            .and_then(toml::Value::as_table_mut)
        else {
            continue;
        };
        for (dep, spec) in deps.iter_mut() {
            if spec.get("workspace").is_some() {
                *spec = inherit(&dependencies[dep], spec);
            } else if let Some(path) = spec.get("path").and_then(toml::Value::as_str) {
                let path = crate_dir()
                    .join(path)
                    .canonicalize()
                    .expect("path dependency");
                spec["path"] = path.to_string_lossy().into_owned().into();
            }
        }
    }
    toml::to_string(&manifest).expect("manifest")
}

/// A dependency inherited from the workspace (`workspace`), with what the crate adds
/// to it (`local`: features, optional).
fn inherit(workspace: &toml::Value, local: &toml::Value) -> toml::Value {
    let mut spec = match workspace {
        toml::Value::String(version) => {
            toml::Table::from_iter([("version".into(), version.as_str().into())])
        }
        other => other.as_table().expect("a dependency table").clone(),
    };
    for (key, value) in local.as_table().expect("a dependency table") {
        match (key.as_str(), spec.get_mut(key)) {
            ("workspace", _) => {}
            ("features", Some(toml::Value::Array(features))) => {
                features.extend(value.as_array().expect("features").iter().cloned())
            }
            _ => {
                spec.insert(key.clone(), value.clone());
            }
        }
    }
    spec.into()
}

fn copy_tree(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).expect("mkdir");
    for entry in std::fs::read_dir(from).expect("read dir") {
        let path = entry.expect("entry").path();
        let dest = to.join(path.file_name().expect("name"));
        if path.is_dir() {
            copy_tree(&path, &dest);
        } else {
            std::fs::copy(&path, &dest).expect("copy");
        }
    }
}
