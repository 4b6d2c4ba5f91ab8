//! What keeps an OME-Zarr read within its bounds where `zarrs` alone would not: a store
//! that reads only regular files and no byte range past a file's end or longer than the
//! read's limit, and decoders for the two codecs whose encoded bytes state the decoded
//! size (blosc's header, zstd's frame content size), which `zarrs` allocates as stated:
//! here a decoded size past what the chunk holds is an error before anything is
//! allocated.

use std::borrow::Cow;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Once};
use zarrs::array::codec::api::{
    register_codec_v2, register_codec_v3, ArrayBytesRaw, BytesRepresentation,
    BytesToBytesCodecTraits, Codec, CodecError, CodecMetadataOptions, CodecOptions,
    CodecRuntimePluginV2, CodecRuntimePluginV3, CodecTraits, CodecTraitsV2, CodecTraitsV3,
    PartialDecoderCapability, PartialEncoderCapability, RecommendedConcurrency,
};
use zarrs::array::codec::{BloscCodec, ZstdCodec};
use zarrs::filesystem::FilesystemStore;
use zarrs::metadata::Configuration;
use zarrs::plugin::{ExtensionAliases, ExtensionName, ZarrVersion, ZarrVersion2, ZarrVersion3};
use zarrs::storage::byte_range::{ByteRange, ByteRangeIterator};
use zarrs::storage::{MaybeBytesIterator, ReadableStorageTraits, StorageError, StoreKey};

/// A filesystem store that reads only regular files (a FIFO would block the read, a
/// device such as `/dev/zero` never end) and only byte ranges inside the file and at
/// most `max_read` bytes long, checked before anything is allocated for them.
pub(super) struct BoundedStore {
    inner: FilesystemStore,
    root: PathBuf,
    max_read: u64,
    /// Where chunks are blosc data that `zarrs` decodes with its own codec (a Zarr v2
    /// array's blosc compressor does not go through the codecs registered here): the
    /// most bytes a chunk file's blosc header may state.
    blosc_chunk_bytes: Option<u64>,
}

impl BoundedStore {
    pub(super) fn new(root: &Path, max_read: u64) -> Result<Self, String> {
        Ok(Self {
            inner: FilesystemStore::new(root).map_err(|e| e.to_string())?,
            root: root.to_path_buf(),
            max_read,
            blosc_chunk_bytes: None,
        })
    }

    /// The store, checking that whole chunk files read are blosc data of at most
    /// `bytes` once decoded.
    pub(super) fn with_blosc_chunks(self, bytes: u64) -> Self {
        Self {
            blosc_chunk_bytes: Some(bytes),
            ..self
        }
    }

    /// The file's size, `None` when there is none; an error for anything but a regular
    /// file.
    fn regular_size(&self, key: &StoreKey) -> Result<Option<u64>, StorageError> {
        let path = self.root.join(key.as_str());
        match crate::files::not_a_regular_file(&path) {
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
            Err(e) => Err(StorageError::Other(format!("{}: {e}", path.display()))),
            Ok(Some(what)) => Err(StorageError::Other(format!(
                "{} is {what}, not a file",
                path.display()
            ))),
            Ok(None) => std::fs::metadata(&path)
                .map(|m| Some(m.len()))
                .map_err(|e| StorageError::Other(format!("{}: {e}", path.display()))),
        }
    }
}

impl ReadableStorageTraits for BoundedStore {
    fn get_partial_many<'a>(
        &'a self,
        key: &StoreKey,
        byte_ranges: ByteRangeIterator<'a>,
    ) -> Result<MaybeBytesIterator<'a>, StorageError> {
        let Some(size) = self.regular_size(key)? else {
            return Ok(None);
        };
        let ranges: Vec<ByteRange> = byte_ranges.collect();
        for range in &ranges {
            let (start, len) = match *range {
                ByteRange::FromStart(start, None) => (start, size.saturating_sub(start)),
                ByteRange::FromStart(start, Some(len)) => (start, len),
                ByteRange::Suffix(len) => (size.saturating_sub(len), len),
            };
            if start.checked_add(len).is_none_or(|end| end > size) {
                return Err(StorageError::Other(format!(
                    "{}: bytes {start}..+{len} asked of a file of {size} bytes",
                    self.root.join(key.as_str()).display()
                )));
            }
            if len > self.max_read {
                return Err(StorageError::Other(format!(
                    "{}: a read of {len} bytes, more than the {} this read may take (the \
                     chunk sizes bound it)",
                    self.root.join(key.as_str()).display(),
                    self.max_read
                )));
            }
        }
        let whole = matches!(ranges.as_slice(), [ByteRange::FromStart(0, None)]);
        let out = self
            .inner
            .get_partial_many(key, Box::new(ranges.into_iter()))?;
        let (Some(limit), true) = (self.blosc_chunk_bytes, whole) else {
            return Ok(out);
        };
        let Some(out) = out else {
            return Ok(None);
        };
        let name = key.as_str().rsplit('/').next().unwrap_or_default();
        if [".zarray", ".zattrs", ".zgroup", "zarr.json"].contains(&name) {
            return Ok(Some(out));
        }
        let out: Vec<_> = out.collect();
        if let Some(Ok(bytes)) = out.first() {
            let stated = blosc_stated_size(bytes);
            if stated.is_some_and(|n| n > limit) {
                return Err(StorageError::Other(format!(
                    "{}: its blosc header states {} bytes, more than the {limit} bytes its \
                     chunk holds",
                    self.root.join(key.as_str()).display(),
                    stated.unwrap_or_default()
                )));
            }
        }
        Ok(Some(Box::new(out.into_iter())))
    }

    fn size_key(&self, key: &StoreKey) -> Result<Option<u64>, StorageError> {
        self.regular_size(key)
    }

    fn supports_get_partial(&self) -> bool {
        true
    }
}

/// Decoded bytes assumed for a chunk whose representation has no bound (variable-sized
/// data types, which the loader refuses before reading, so no read reaches it).
const UNBOUNDED_DECODE_BYTES: u64 = 1 << 30;

/// Registers [`BoundedDecode`] for blosc and zstd (once per process): `zarrs` consults
/// codecs registered at run time before its own.
pub(super) fn register_bounded_codecs() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        fn wrap(codec: Codec, kind: Kind) -> Codec {
            match codec {
                Codec::BytesToBytes(inner) => {
                    Codec::BytesToBytes(Arc::new(BoundedDecode { inner, kind }))
                }
                other => other,
            }
        }
        // The handles are dropped: the codecs stay registered for the process.
        let _ = register_codec_v3(CodecRuntimePluginV3::new(
            <ZstdCodec as ExtensionAliases<ZarrVersion3>>::matches_name,
            |m| <ZstdCodec as CodecTraitsV3>::create(m).map(|c| wrap(c, Kind::Zstd)),
        ));
        let _ = register_codec_v2(CodecRuntimePluginV2::new(
            <ZstdCodec as ExtensionAliases<ZarrVersion2>>::matches_name,
            |m| <ZstdCodec as CodecTraitsV2>::create(m).map(|c| wrap(c, Kind::Zstd)),
        ));
        let _ = register_codec_v3(CodecRuntimePluginV3::new(
            <BloscCodec as ExtensionAliases<ZarrVersion3>>::matches_name,
            |m| <BloscCodec as CodecTraitsV3>::create(m).map(|c| wrap(c, Kind::Blosc)),
        ));
        let _ = register_codec_v2(CodecRuntimePluginV2::new(
            <BloscCodec as ExtensionAliases<ZarrVersion2>>::matches_name,
            |m| <BloscCodec as CodecTraitsV2>::create(m).map(|c| wrap(c, Kind::Blosc)),
        ));
    });
}

#[derive(Clone, Copy, Debug)]
enum Kind {
    Zstd,
    Blosc,
}

/// `zarrs`' own codec, decoding only what fits the chunk: zstd through a stream that
/// stops one byte past the chunk's size, blosc after its header's size is checked.
/// Partial decoding decodes the whole (bounded) chunk.
#[derive(Debug)]
struct BoundedDecode {
    inner: Arc<dyn BytesToBytesCodecTraits>,
    kind: Kind,
}

impl ExtensionName for BoundedDecode {
    fn name(&self, version: ZarrVersion) -> Option<Cow<'static, str>> {
        self.inner.name(version)
    }
}

impl CodecTraits for BoundedDecode {
    fn as_any(&self) -> &dyn std::any::Any {
        self
    }

    fn configuration(
        &self,
        version: ZarrVersion,
        options: &CodecMetadataOptions,
    ) -> Option<Configuration> {
        self.inner.configuration(version, options)
    }

    fn partial_decoder_capability(&self) -> PartialDecoderCapability {
        PartialDecoderCapability {
            partial_read: false,
            partial_decode: false,
        }
    }

    fn partial_encoder_capability(&self) -> PartialEncoderCapability {
        self.inner.partial_encoder_capability()
    }
}

impl BytesToBytesCodecTraits for BoundedDecode {
    fn into_dyn(self: Arc<Self>) -> Arc<dyn BytesToBytesCodecTraits> {
        self
    }

    fn recommended_concurrency(
        &self,
        decoded_representation: &BytesRepresentation,
    ) -> Result<RecommendedConcurrency, CodecError> {
        self.inner.recommended_concurrency(decoded_representation)
    }

    fn encoded_representation(
        &self,
        decoded_representation: &BytesRepresentation,
    ) -> BytesRepresentation {
        self.inner.encoded_representation(decoded_representation)
    }

    fn encode<'a>(
        &self,
        decoded_value: ArrayBytesRaw<'a>,
        options: &CodecOptions,
    ) -> Result<ArrayBytesRaw<'a>, CodecError> {
        self.inner.encode(decoded_value, options)
    }

    fn decode<'a>(
        &self,
        encoded_value: ArrayBytesRaw<'a>,
        decoded_representation: &BytesRepresentation,
        options: &CodecOptions,
    ) -> Result<ArrayBytesRaw<'a>, CodecError> {
        let limit = decoded_representation
            .size()
            .unwrap_or(UNBOUNDED_DECODE_BYTES);
        let too_large = |what: String| {
            CodecError::Other(format!(
                "{what}, more than the {limit} bytes its chunk holds"
            ))
        };
        match self.kind {
            Kind::Zstd => {
                // The window (the decoder's buffer) no larger than the chunk, or 8 MiB
                // (what zstd's levels up to 19 use when they do not know the size they
                // compress): a frame may ask for 128 MiB whatever it holds.
                let window_log = (64 - limit.leading_zeros()).clamp(23, 31);
                let mut decoded = Vec::new();
                zstd::stream::read::Decoder::new(&encoded_value[..])
                    .and_then(|mut d| {
                        d.window_log_max(window_log)?;
                        d.take(limit + 1).read_to_end(&mut decoded)
                    })
                    .map_err(|e| CodecError::Other(format!("zstd: {e}")))?;
                if decoded.len() as u64 > limit {
                    return Err(too_large("zstd data decodes to more".into()));
                }
                Ok(Cow::Owned(decoded))
            }
            Kind::Blosc => {
                if let Some(n) = blosc_stated_size(&encoded_value).filter(|&n| n > limit) {
                    return Err(too_large(format!("a blosc header states {n} bytes")));
                }
                self.inner
                    .decode(encoded_value, decoded_representation, options)
            }
        }
    }
}

/// The decoded size a blosc header states (its bytes 4..8, little endian).
fn blosc_stated_size(encoded: &[u8]) -> Option<u64> {
    let n = encoded.get(4..8)?;
    Some(u64::from(u32::from_le_bytes([n[0], n[1], n[2], n[3]])))
}
