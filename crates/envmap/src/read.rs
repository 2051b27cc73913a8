//! Reading OpenEXR and Radiance HDR files. The format is chosen by the first bytes, never by the
//! extension; the size in the header is checked against [`Limits`] before anything the size of
//! the image is allocated or decoded.

use std::io::{BufRead, BufReader, Read, Seek, SeekFrom};
use std::path::Path;

use crate::error::Error;
use crate::map::{EnvMap, check_latlong_shape, check_not_empty, check_radiance};

/// The largest map the readers accept and the memory the job reading it may use, both checked
/// against the header before anything the size of the image is allocated or decoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Limits {
    pub max_width: usize,
    pub max_height: usize,
    /// The memory budget of the job, in bytes ([`DEFAULT_MAX_MEMORY`]).
    pub max_memory: u64,
    /// What the job needs per texel of the map, in bytes: its peak memory is estimated as
    /// `width x height x bytes_per_texel`. [`READ_BYTES_PER_TEXEL`] covers reading alone; a tool
    /// that holds more per texel says so (the `bake` crate's stages do).
    pub bytes_per_texel: u64,
}

/// The default memory budget of a job: 4 GiB.
pub const DEFAULT_MAX_MEMORY: u64 = 4 << 30;

/// The peak memory of reading a map, per texel, in bytes: the decoded `f32` RGB image (12)
/// and what the decoders hold beside it at their peak (the `exr` crate's channels, 12, the
/// `image` crate's Radiance pixels and their conversion, 16), with room to spare.
pub const READ_BYTES_PER_TEXEL: u64 = 32;

impl Default for Limits {
    /// 16384 x 8192 (a 16k lat-long map, 1.5 GiB of `f32` RGB), [`DEFAULT_MAX_MEMORY`],
    /// [`READ_BYTES_PER_TEXEL`].
    fn default() -> Self {
        Limits {
            max_width: 16384,
            max_height: 8192,
            max_memory: DEFAULT_MAX_MEMORY,
            bytes_per_texel: READ_BYTES_PER_TEXEL,
        }
    }
}

impl Limits {
    /// The default limits for a job that needs `bytes_per_texel` per texel of the map and may
    /// use `max_memory` bytes.
    pub fn for_job(bytes_per_texel: u64, max_memory: u64) -> Limits {
        Limits { max_memory, bytes_per_texel, ..Limits::default() }
    }

    /// Checks a map's size from its header: within the largest size, and the job's estimated
    /// memory within the budget. The estimate is then reserved once, fallibly, and released:
    /// where the system cannot give that much (an address-space limit, `ulimit -v`), the job
    /// stops here with an error instead of aborting on an allocation later.
    pub fn check(&self, width: usize, height: usize) -> Result<(), Error> {
        if width > self.max_width || height > self.max_height {
            return Err(Error::LimitExceeded(format!(
                "{width} x {height} is larger than the limit of {} x {}",
                self.max_width, self.max_height
            )));
        }
        let need = (width as u64).saturating_mul(height as u64).saturating_mul(self.bytes_per_texel);
        if need > self.max_memory {
            return Err(Error::LimitExceeded(format!(
                "a {width} x {height} map needs about {} for this job ({} bytes per texel), more than the memory \
                 budget of {} (--max-memory)",
                format_bytes(need),
                self.bytes_per_texel,
                format_bytes(self.max_memory)
            )));
        }
        let mut probe: Vec<u8> = Vec::new();
        probe.try_reserve_exact(usize::try_from(need).unwrap_or(usize::MAX)).map_err(|_| {
            Error::LimitExceeded(format!(
                "a {width} x {height} map needs about {} for this job and the system cannot provide it",
                format_bytes(need)
            ))
        })?;
        Ok(())
    }
}

/// A size for people: bytes, KiB, MiB or GiB with up to one decimal (`1.5 GiB`, `4 GiB`).
pub fn format_bytes(bytes: u64) -> String {
    let units = [("GiB", 1u64 << 30), ("MiB", 1 << 20), ("KiB", 1 << 10)];
    for (name, size) in units {
        if bytes >= size {
            let value = bytes as f64 / size as f64;
            let text = format!("{value:.1}");
            return format!("{} {name}", text.strip_suffix(".0").unwrap_or(&text));
        }
    }
    format!("{bytes} bytes")
}

/// An RGB radiance image of any shape: what [`read_image`] returns for files that need not be
/// environment maps (tables, test images). The readers fill it only with images that pass every
/// check of [`load_with_limits`] except the 2:1 shape; the fields are public, so
/// `EnvMap::try_from` checks everything again. Map tools call [`load`].
#[derive(Clone, Debug, PartialEq)]
pub struct HdrImage {
    pub width: usize,
    pub height: usize,
    /// Three values (R, G, B) per texel, row-major, top row first.
    pub rgb: Vec<f32>,
}

impl TryFrom<HdrImage> for EnvMap {
    type Error = Error;

    fn try_from(image: HdrImage) -> Result<EnvMap, Error> {
        EnvMap::new(image.width, image.height, image.rgb)
    }
}

/// Loads a lat-long environment map with the default [`Limits`]. See [`load_with_limits`].
pub fn load(path: &Path) -> Result<EnvMap, Error> {
    load_with_limits(path, &Limits::default())
}

/// Loads a lat-long environment map from an OpenEXR or Radiance HDR file (the first bytes decide)
/// and checks that it is one: non-empty, within `limits`, `width == 2 * height` (all three from
/// the header, before decoding), and every value finite and non-negative. Only a regular file is
/// read: a FIFO or a device is refused without blocking ([`fsguard::open_regular`]).
pub fn load_with_limits(path: &Path, limits: &Limits) -> Result<EnvMap, Error> {
    let image = decode(BufReader::new(fsguard::open_regular(path)?), limits, check_latlong_shape)?;
    Ok(EnvMap::from_checked(image.width, image.height, image.rgb))
}

/// Reads an OpenEXR or Radiance HDR image of any shape: the checks of [`load_with_limits`] except
/// the 2:1 shape.
pub fn read_image(path: &Path, limits: &Limits) -> Result<HdrImage, Error> {
    decode(BufReader::new(fsguard::open_regular(path)?), limits, check_not_empty)
}

/// [`load_with_limits`] from bytes in memory.
pub fn load_from_memory(bytes: &[u8], limits: &Limits) -> Result<EnvMap, Error> {
    let image = decode(std::io::Cursor::new(bytes), limits, check_latlong_shape)?;
    Ok(EnvMap::from_checked(image.width, image.height, image.rgb))
}

/// [`read_image`] from bytes in memory.
pub fn read_image_from_memory(bytes: &[u8], limits: &Limits) -> Result<HdrImage, Error> {
    decode(std::io::Cursor::new(bytes), limits, check_not_empty)
}

/// OpenEXR's magic number, `76 2f 31 01`.
const EXR_MAGIC: [u8; 4] = [0x76, 0x2f, 0x31, 0x01];

fn decode<R: BufRead + Seek>(
    mut reader: R,
    limits: &Limits,
    check_shape: fn(usize, usize) -> Result<(), Error>,
) -> Result<HdrImage, Error> {
    let mut magic = Vec::with_capacity(4);
    reader.by_ref().take(4).read_to_end(&mut magic)?;
    reader.seek(SeekFrom::Start(0))?;
    let image = if magic.is_empty() {
        return Err(Error::Invalid("empty file".into()));
    } else if magic.len() < 4 && (EXR_MAGIC.starts_with(&magic) || b"#?".starts_with(&magic)) {
        return Err(Error::Invalid(format!("truncated: the file is {} bytes long", magic.len())));
    } else if magic == EXR_MAGIC {
        decode_exr(reader, limits, check_shape)?
    } else if magic.starts_with(b"#?") {
        decode_hdr(reader, limits, check_shape)?
    } else {
        let hex: Vec<String> = magic.iter().map(|b| format!("{b:02x}")).collect();
        return Err(Error::Unsupported(format!(
            "unknown file format (starts with {}): expected OpenEXR (76 2f 31 01) or Radiance HDR (#?)",
            hex.join(" ")
        )));
    };
    Ok(image)
}

/// Radiance HDR through the `image` crate: the new (per-component) and the old run-length
/// schemes and flat pixels; `FORMAT=32-bit_rle_rgbe` only, `-Y H +X W` orientation only.
/// `EXPOSURE` and `COLORCORR` are not applied: the values are the pixels as stored, like every
/// renderer's loader does.
fn decode_hdr<R: BufRead>(
    mut reader: R,
    limits: &Limits,
    check_shape: fn(usize, usize) -> Result<(), Error>,
) -> Result<HdrImage, Error> {
    // Radiance writes the name of the writing program after "#?" ("#?RADIANCE", "#?RGBE", ...);
    // the `image` decoder accepts only "#?RADIANCE", so the first line is replaced by that.
    let mut signature = Vec::new();
    reader.by_ref().take(128).read_until(b'\n', &mut signature)?;
    if signature.last() != Some(&b'\n') {
        return Err(Error::Invalid("radiance hdr: truncated or overlong signature line".into()));
    }
    let hdr_error = |e| Error::from_image("radiance hdr", e);
    let decoder = image::codecs::hdr::HdrDecoder::new((&b"#?RADIANCE\n"[..]).chain(reader)).map_err(hdr_error)?;
    let (width, height) = image::ImageDecoder::dimensions(&decoder);
    let (width, height) = (width as usize, height as usize);
    limits.check(width, height)?;
    check_shape(width, height)?;
    let rgb = image::DynamicImage::from_decoder(decoder).map_err(hdr_error)?.into_rgb32f().into_raw();
    check_radiance(width, &["R", "G", "B"], &rgb)?;
    Ok(HdrImage { width, height, rgb })
}

/// OpenEXR through the `exr` crate: scanline or tiled, any compression it reads, the full
/// resolution level of mip- or rip-mapped files. The first flat (not deep) part is read; its
/// data window is the image (the display window is ignored). It must hold `R`, `G` and `B` (any
/// other channel, `A` included, is ignored) or else `Y` (grey: R = G = B = Y), in `f16` or `f32`.
fn decode_exr<R: BufRead + Seek>(
    reader: R,
    limits: &Limits,
    check_shape: fn(usize, usize) -> Result<(), Error>,
) -> Result<HdrImage, Error> {
    use exr::compression::Compression;
    use exr::prelude::{FlatSamples, ReadChannels, ReadLayers};

    let mut reader = reader;
    let file_len = reader.seek(SeekFrom::End(0))?;
    reader.seek(SeekFrom::Start(0))?;
    // Headers only; the offset tables and the pixels are read by `from_chunks` below.
    let chunks = exr::block::read(reader, false)?;
    let header = chunks
        .headers()
        .iter()
        .find(|header| !header.deep)
        .ok_or_else(|| Error::Unsupported("openexr: deep data only, no flat image".into()))?;
    let (width, height) = (header.layer_size.0, header.layer_size.1);
    limits.check(width, height)?;
    check_shape(width, height)?;
    let names = pick_exr_channels(header)?;
    check_exr_payload(header, width, height, file_len)?;

    let read = exr::prelude::read().no_deep_data().largest_resolution_level().all_channels().first_valid_layer();
    let read = read.all_attributes().pedantic();
    // The `exr` crate's B44 decompressor overflows on some damaged data (1.74.2,
    // `compression/b44/mod.rs`); with overflow checks on (debug and test builds) that is a
    // panic, which inside the crate's thread pool aborts the process. B44 files, and every file
    // in a build with debug assertions (where the crate's own assertions can fire too), are
    // decoded on this thread instead, and a panic of the decoder becomes an error.
    let b44 = chunks.headers().iter().any(|h| matches!(h.compression, Compression::B44 | Compression::B44A));
    let read = if b44 || cfg!(debug_assertions) { read.non_parallel() } else { read };
    let image = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| read.from_chunks(chunks)))
        .map_err(|_| Error::Invalid("openexr: the decoder failed on damaged data".into()))??;
    let layer = image.layer_data;
    if (layer.size.0, layer.size.1) != (width, height) {
        return Err(Error::Invalid("openexr: the decoded layer is not the one whose header was checked".into()));
    }
    let channel = |name: &str| -> Result<Vec<f32>, Error> {
        let found = layer.channel_data.list.iter().find(|c| c.name == *name);
        let values: Vec<f32> = match found.map(|c| &c.sample_data) {
            Some(FlatSamples::F32(values)) => values.clone(),
            Some(FlatSamples::F16(values)) => values.iter().map(|v| v.to_f32()).collect(),
            Some(FlatSamples::U32(_)) | None => {
                return Err(Error::Invalid(format!("openexr: channel {name} differs from its header")));
            }
        };
        if values.len() != width * height {
            return Err(Error::Invalid(format!("openexr: channel {name} has {} samples", values.len())));
        }
        check_radiance(width, &[name], &values)?;
        Ok(values)
    };
    let rgb = match names {
        ExrChannels::Rgb => {
            let (r, g, b) = (channel("R")?, channel("G")?, channel("B")?);
            r.iter().zip(&g).zip(&b).flat_map(|((&r, &g), &b)| [r, g, b]).collect()
        }
        ExrChannels::Y => channel("Y")?.iter().flat_map(|&y| [y, y, y]).collect(),
    };
    Ok(HdrImage { width, height, rgb })
}

/// Checks that the file can hold the payload its header declares before anything the size of the
/// image is allocated: every chunk has an entry in the offset table (8 bytes) and at least a
/// 4-byte coordinate, a 4-byte size and one byte of data; an uncompressed part holds every
/// sample. An 808-byte header declaring a 16384 x 8192 image is truncated, not a reason to
/// allocate 1.5 GiB.
fn check_exr_payload(
    header: &exr::meta::header::Header,
    width: usize,
    height: usize,
    file_len: u64,
) -> Result<(), Error> {
    let chunks = header.chunk_count as u64;
    let mut least = chunks.saturating_mul(8 + 9);
    if header.compression == exr::compression::Compression::Uncompressed {
        let sample_bytes: u64 = header.channels.list.iter().map(|c| c.sample_type.bytes_per_sample() as u64).sum();
        let samples = (width as u64).saturating_mul(height as u64).saturating_mul(sample_bytes);
        least = least.max(samples);
    }
    if file_len < least {
        return Err(Error::Invalid(format!(
            "openexr: truncated: a {width} x {height} image in {chunks} chunks needs at least {least} bytes, the \
             file has {file_len}"
        )));
    }
    Ok(())
}

enum ExrChannels {
    Rgb,
    Y,
}

/// Which channels hold the radiance, decided from the header so that unsupported files are
/// rejected before any pixel is decoded.
fn pick_exr_channels(header: &exr::meta::header::Header) -> Result<ExrChannels, Error> {
    use exr::meta::attribute::SampleType;

    let list = &header.channels.list;
    let find = |name: &str| list.iter().find(|c| c.name == *name);
    let (picked, names): (ExrChannels, &[&str]) = if ["R", "G", "B"].iter().all(|n| find(n).is_some()) {
        (ExrChannels::Rgb, &["R", "G", "B"])
    } else if find("Y").is_some() {
        if find("RY").is_some() || find("BY").is_some() {
            return Err(Error::Unsupported("openexr: luminance-chroma (Y, RY, BY) images".into()));
        }
        (ExrChannels::Y, &["Y"])
    } else {
        let found: Vec<String> = list.iter().map(|c| c.name.to_string()).collect();
        return Err(Error::Unsupported(format!(
            "openexr: no R, G, B or Y channels (found {})",
            if found.is_empty() { "none".to_string() } else { found.join(", ") }
        )));
    };
    for name in names {
        let Some(channel) = find(name) else { continue };
        if channel.sample_type == SampleType::U32 {
            return Err(Error::Unsupported(format!("openexr: channel {name} holds u32 samples, not radiance")));
        }
        if channel.sampling != exr::math::Vec2(1, 1) {
            return Err(Error::Unsupported(format!("openexr: channel {name} is subsampled")));
        }
    }
    Ok(picked)
}
