use super::*;
use crate::{load_within_seconds, make_fifo};
use serde_json::json;

/// An OME-Zarr 0.5 image at `dir/img.zarr` with one level, `0`, of `array` (a Zarr v3
/// array's metadata), and `chunks` [(key under `0/`, bytes)].
fn image(dir: &Path, axes: &[&str], array: serde_json::Value, chunks: &[(&str, &[u8])]) -> PathBuf {
    let root = dir.join("img.zarr");
    let axes: Vec<_> = axes
        .iter()
        .map(|&a| match a {
            "t" => json!({"name": "t", "type": "time"}),
            a => json!({"name": a, "type": "space", "unit": "millimeter"}),
        })
        .collect();
    let group = json!({"zarr_format": 3, "node_type": "group", "attributes": {"ome": {
        "version": "0.5", "multiscales": [{"axes": axes, "datasets": [{"path": "0",
        "coordinateTransformations": [{"type": "scale", "scale": vec![1.0; axes.len()]}]}]}]}}});
    std::fs::create_dir_all(root.join("0")).unwrap();
    std::fs::write(root.join("zarr.json"), group.to_string()).unwrap();
    std::fs::write(root.join("0/zarr.json"), array.to_string()).unwrap();
    for (key, bytes) in chunks {
        let path = root.join("0").join(key);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, bytes).unwrap();
    }
    root
}

fn array(shape: &[u64], chunk: &[u64], codecs: serde_json::Value) -> serde_json::Value {
    json!({"zarr_format": 3, "node_type": "array", "shape": shape, "data_type": "uint8",
        "chunk_grid": {"name": "regular", "configuration": {"chunk_shape": chunk}},
        "chunk_key_encoding": {"name": "default"}, "fill_value": 0, "codecs": codecs})
}

fn error(path: &Path) -> String {
    load_within_seconds(path, 20).unwrap_err().to_string()
}

#[test]
fn chunk_sizes_and_counts_are_checked_before_any_chunk_is_read() {
    let dir = tempfile::tempdir().unwrap();
    let bytes = json!([{"name": "bytes"}]);
    // A chunk larger than the volume read (and a 256³ chunk): it would be decoded whole.
    let e = error(&image(
        dir.path(),
        &["z", "y", "x"],
        array(&[2, 2, 2], &[1024, 1024, 1024], bytes.clone()),
        &[],
    ));
    assert!(
        e.contains("img.zarr") && e.contains("[1024, 1024, 1024]") && e.contains("decoded whole"),
        "{e}"
    );
    // 4M chunks of one voxel: minutes of file opens.
    let e = error(&image(
        dir.path(),
        &["z", "y", "x"],
        array(&[64, 128, 512], &[1, 1, 1], bytes.clone()),
        &[],
    ));
    assert!(
        e.contains("[64, 128, 512] chunks") && e.contains("262144"),
        "{e}"
    );
    // A shard of 2^60 inner chunks, whose index would be read whole (zarrs overflowed).
    let sharded = json!([{"name": "sharding_indexed", "configuration": {"chunk_shape": [1, 1, 1],
        "codecs": [{"name": "bytes"}], "index_codecs": [{"name": "bytes"}], "index_location": "end"}}]);
    let e = error(&image(
        dir.path(),
        &["z", "y", "x"],
        array(&[4, 4, 4], &[1 << 20, 1 << 20, 1 << 20], sharded),
        &[("c/0/0/0", &[0xff; 64])],
    ));
    assert!(e.contains("decoded whole"), "{e}");
    let sharded = json!([{"name": "sharding_indexed", "configuration": {"chunk_shape": [1, 1, 1],
        "codecs": [{"name": "bytes"}], "index_codecs": [{"name": "bytes"}], "index_location": "end"}}]);
    let e = error(&image(
        dir.path(),
        &["z", "y", "x"],
        array(&[64, 64, 128], &[64, 64, 128], sharded),
        &[("c/0/0/0", &[0xff; 64])],
    ));
    assert!(e.contains("inner chunks per shard"), "{e}");
    // A shard larger than the array, of a small index (64 inner chunks) but past the
    // end of its 64-byte file: refused before anything is allocated for it.
    let sharded = json!([{"name": "sharding_indexed", "configuration": {"chunk_shape": [2, 2, 2],
        "codecs": [{"name": "bytes"}], "index_codecs": [{"name": "bytes"}], "index_location": "end"}}]);
    let e = error(&image(
        dir.path(),
        &["z", "y", "x"],
        array(&[4, 4, 4], &[8, 8, 8], sharded),
        &[("c/0/0/0", &[0xff; 64])],
    ));
    assert!(
        e.contains("c/0/0/0") && e.contains("asked of a file of 64 bytes"),
        "{e}"
    );
}

#[test]
fn decoded_sizes_that_zstd_and_blosc_state_are_checked() {
    let dir = tempfile::tempdir().unwrap();
    // 100 bytes of zstd data for a chunk of 8: decoding stops at the 9th byte.
    let zstd = zstd::bulk::compress(&[7u8; 100], 1).unwrap();
    let codecs = json!([{"name": "bytes"}, {"name": "zstd", "configuration": {"level": 1, "checksum": false}}]);
    let e = error(&image(
        dir.path(),
        &["z", "y", "x"],
        array(&[2, 2, 2], &[2, 2, 2], codecs.clone()),
        &[("c/0/0/0", &zstd)],
    ));
    assert!(
        e.contains("img.zarr") && e.contains("more than the 8 bytes its chunk holds"),
        "{e}"
    );
    // A frame stating 2^40 bytes (zarrs allocated them): refused by its window.
    let mut frame = vec![0x28, 0xb5, 0x2f, 0xfd, 0xe0];
    frame.extend((1u64 << 40).to_le_bytes());
    frame.extend([1, 0, 0]);
    let e = error(&image(
        dir.path(),
        &["z", "y", "x"],
        array(&[2, 2, 2], &[2, 2, 2], codecs),
        &[("c/0/0/0", &frame)],
    ));
    assert!(e.contains("zstd"), "{e}");
    // A blosc header stating 2 GiB, in Zarr v3 and as a Zarr v2 compressor.
    let mut blosc = vec![2, 1, 3, 1];
    blosc.extend(0x7fff_ff00u32.to_le_bytes());
    blosc.extend(0x1_0000u32.to_le_bytes());
    blosc.extend(32u32.to_le_bytes());
    blosc.extend([0; 16]);
    let codecs = json!([{"name": "bytes"}, {"name": "blosc", "configuration": {"typesize": 1,
        "cname": "lz4", "clevel": 5, "shuffle": "noshuffle", "blocksize": 0}}]);
    let e = error(&image(
        dir.path(),
        &["z", "y", "x"],
        array(&[2, 2, 2], &[2, 2, 2], codecs),
        &[("c/0/0/0", &blosc)],
    ));
    assert!(e.contains("blosc header states 2147483392 bytes"), "{e}");
    let root = dir.path().join("img.zarr");
    std::fs::remove_dir_all(&root).unwrap();
    std::fs::create_dir_all(root.join("0")).unwrap();
    std::fs::write(root.join(".zgroup"), r#"{"zarr_format": 2}"#).unwrap();
    std::fs::write(root.join(".zattrs"), json!({"multiscales": [{"version": "0.4",
        "axes": [{"name": "z", "type": "space"}, {"name": "y", "type": "space"}, {"name": "x", "type": "space"}],
        "datasets": [{"path": "0", "coordinateTransformations": [{"type": "scale", "scale": [1, 1, 1]}]}]}]}).to_string()).unwrap();
    std::fs::write(
        root.join("0/.zarray"),
        json!({"zarr_format": 2, "shape": [2, 2, 2], "chunks": [2, 2, 2],
        "dtype": "|u1", "compressor": {"id": "blosc", "cname": "lz4", "clevel": 5, "shuffle": 1},
        "fill_value": 0, "order": "C", "filters": null})
        .to_string(),
    )
    .unwrap();
    std::fs::write(root.join("0/0.0.0"), &blosc).unwrap();
    let e = error(&root);
    assert!(
        e.contains("0/0.0.0") && e.contains("blosc header states 2147483392 bytes"),
        "{e}"
    );
}

#[test]
fn odd_shapes_units_and_files_fail_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    let bytes = json!([{"name": "bytes"}]);
    // Sides whose product overflows u64 (this panicked).
    let e = error(&image(
        dir.path(),
        &["z", "y", "x"],
        array(&[1 << 62, 1 << 62, 1 << 62], &[1, 1, 1], bytes.clone()),
        &[],
    ));
    assert!(e.contains("no resolution level fits"), "{e}");
    // A time axis of no entries.
    let e = error(&image(
        dir.path(),
        &["t", "z", "y", "x"],
        array(&[0, 2, 2, 2], &[1, 2, 2, 2], bytes.clone()),
        &[],
    ));
    assert!(e.contains("axis t has no entries"), "{e}");
    // A scale past the spacing limits.
    let root = image(
        dir.path(),
        &["z", "y", "x"],
        array(&[2, 2, 2], &[2, 2, 2], bytes.clone()),
        &[],
    );
    let group = std::fs::read_to_string(root.join("zarr.json")).unwrap();
    std::fs::write(
        root.join("zarr.json"),
        group.replace("[1.0,1.0,1.0]", "[1e-12,1.0,1.0]"),
    )
    .unwrap();
    let e = error(&root);
    assert!(
        e.contains("coordinateTransformations") && e.contains("spacing"),
        "{e}"
    );
    // A chunk that is a FIFO: refused by name, not opened (the read would block).
    let root = image(
        dir.path(),
        &["z", "y", "x"],
        array(&[2, 2, 2], &[2, 2, 2], bytes),
        &[],
    );
    std::fs::create_dir_all(root.join("0/c/0/0")).unwrap();
    if make_fifo(&root.join("0/c/0/0/0")) {
        let e = error(&root);
        assert!(e.contains("c/0/0/0 is a named pipe (FIFO)"), "{e}");
    }
}
