//! A toy scene field added the way OVERVIEW.md's recipe ("Extending dvr", "A scene
//! field") adds a real one, to a copy of this crate: a field of `[camera]` with
//! `#[serde(default)]` (and its value in `CameraSpec::default()`), and its range check
//! in `CameraSpec::check`, naming it. A struct cannot grow a field while its tests run,
//! so the recipe is applied to the copy's sources, which build and run their own tests:
//! the copy's `to_toml_round_trips`, and the toy's (an existing scene file loads, the
//! toy round-trips, an out-of-range toy is refused naming `camera.toy`).
//!
//! A second copy skips the two steps (no `#[serde(default)]`, no check) and must fail:
//! the example scene, written before the field, no longer loads, and the out-of-range
//! toy is accepted. So the test shows both that the recipe works and that its checks
//! see a skipped step.
//!
//! The copies are a workspace of their own in this build's target folder
//! (`copies.rs`): a run recompiles them incrementally (seconds); the first run in a
//! target folder builds them whole (40 to 60 s on 2 cores).

mod copies;

use copies::{outcome, Copies, Edit};

/// Step 1: the field, `#[serde(default)]` since a file may leave it out.
const FIELD: Edit = Edit {
    file: "src/camera.rs",
    after: "    pub fov_y_degrees: f64,\n",
    text: "    /// A toy setting in [0, 1]; 0 where a file leaves it out.\n    \
           #[serde(default)]\n    pub toy: f64,\n",
};

/// Step 1 with its `#[serde(default)]` left out.
const FIELD_WITHOUT_DEFAULT: Edit = Edit {
    text: "    /// A toy setting in [0, 1].\n    pub toy: f64,\n",
    ..FIELD
};

/// Step 1's value where the section is made in code (the compiler asks for it).
const DEFAULT_VALUE: Edit = Edit {
    file: "src/camera.rs",
    after: "            fov_y_degrees: DEFAULT_FOV_Y_DEGREES,\n",
    text: "            toy: 0.0,\n",
};

/// Step 2: the section's check, naming the field in its error.
const CHECK: Edit = Edit {
    file: "src/camera.rs",
    after: "        check_fov(ctx, &format!(\"{field}.fov_y_degrees\"), self.fov_y_degrees)?;\n",
    text: "        if !(0.0..=1.0).contains(&self.toy) {\n            \
           return Err(ctx.invalid(format!(\"{field}.toy\"), format!(\"{} is not in [0, 1]\", self.toy)));\n        \
           }\n",
};

/// The toy's tests, a module of the copy.
const TESTS_MOD: Edit = Edit {
    file: "src/lib.rs",
    after: "mod tests;\n",
    text: "#[cfg(test)]\nmod toy_tests;\n",
};

const TOY_TESTS: &str = r#"//! The toy field's tests (written by tests/toy_field.rs).
use super::*;

/// A scene whose `[camera]` sets the toy to `value`.
fn with_toy(value: &str) -> String {
    format!(
        "[volume]\nbuiltin = \"cloud\"\n[transfer]\na = \"cloud\"\n[[light]]\nkind = \"point\"\n\
         position = [1.0, 1.0, 1.0]\nintensity = 10\n[camera]\nposition = [0.0, 1.5, 0.0]\n\
         toy = {value}\n"
    )
}

#[test]
fn a_scene_file_without_the_toy_loads() {
    let path = dvr_volume::assets::assets_dir().join("scenes/example.toml");
    let scene = Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(scene.camera.toy, 0.0);
}

#[test]
fn the_toy_round_trips() {
    let scene = Scene::from_toml_str(&with_toy("0.25"), "toy.toml").unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(scene.camera.toy, 0.25);
    let text = scene.to_toml().expect("writes");
    let back = Scene::from_toml_str(&text, "back.toml").unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(back, scene);
}

#[test]
fn an_out_of_range_toy_is_refused_naming_it() {
    match Scene::from_toml_str(&with_toy("2.0"), "toy.toml") {
        Ok(_) => panic!("toy = 2 accepted"),
        Err(e) => assert!(e.to_string().contains("camera.toy"), "{e}"),
    }
}
"#;

/// The tests each copy runs: the recipe's named check and the toy's.
const FILTERS: &[&str] = &["to_toml_round_trips", "toy_tests::"];

#[test]
fn a_toy_field_is_a_field_and_its_check() {
    let started = std::time::Instant::now();
    let (good, skipped) = ("scene-with-toy", "scene-with-toy-steps-skipped");
    let toy_tests = [("src/toy_tests.rs", TOY_TESTS)];
    let mut copies = Copies::new("toy-field");
    copies.add(
        "scene",
        good,
        &toy_tests,
        &[&FIELD, &DEFAULT_VALUE, &CHECK, &TESTS_MOD],
    );
    copies.add(
        "scene-skipped",
        skipped,
        &toy_tests,
        &[&FIELD_WITHOUT_DEFAULT, &DEFAULT_VALUE, &TESTS_MOD],
    );
    copies
        .build()
        .unwrap_or_else(|log| panic!("the copies do not build:\n{log}"));
    let passed = |log: &str, test: &str| outcome(log, test) == Some("ok");

    let (ok, log) = copies.test(good, FILTERS);
    assert!(ok, "the recipe followed, the copy's tests fail:\n{log}");
    for test in [
        "tests::to_toml_round_trips",
        "toy_tests::a_scene_file_without_the_toy_loads",
        "toy_tests::the_toy_round_trips",
        "toy_tests::an_out_of_range_toy_is_refused_naming_it",
    ] {
        assert!(passed(&log, test), "{test} did not pass:\n{log}");
    }

    // Without `#[serde(default)]` the scenes written before the field fail to load;
    // without the check the out-of-range toy is accepted.
    let (ok, log) = copies.test(skipped, FILTERS);
    assert!(
        !ok,
        "the recipe's steps skipped, the copy's tests pass:\n{log}"
    );
    for (test, why) in [
        ("tests::to_toml_round_trips", "missing field `toy`"),
        (
            "toy_tests::a_scene_file_without_the_toy_loads",
            "missing field `toy`",
        ),
        (
            "toy_tests::an_out_of_range_toy_is_refused_naming_it",
            "toy = 2 accepted",
        ),
    ] {
        assert_eq!(outcome(&log, test), Some("FAILED"), "{test}:\n{log}");
        assert!(log.contains(why), "{test} should fail with {why:?}:\n{log}");
    }
    assert!(passed(&log, "toy_tests::the_toy_round_trips"), "{log}");
    eprintln!("built and ran both copies in {:.1?}", started.elapsed());
}
