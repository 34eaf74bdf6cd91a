//! Reading environment maps: Radiance `.hdr` and OpenEXR (scanline or tiled;
//! uncompressed, RLE, ZIPS, ZIP, PIZ, PXR24, B44, B44A through the `exr`
//! crate). A compression the reader cannot decode (DWAA, DWAB) is named in
//! the error. `sky` is the built-in procedural sky.

use lobe::envmap::{EnvMap, TexelBuffer};
use std::path::{Path, PathBuf};

#[derive(Debug, thiserror::Error)]
pub enum LoadError {
    #[error("{path}: cannot read the file: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}: {message}")]
    Format { path: PathBuf, message: String },
    #[error("{path}: {source}")]
    Map {
        path: PathBuf,
        source: lobe::envmap::EnvMapError,
    },
}

/// The built-in sky's resolution and sun.
pub const SKY: (usize, usize, f64, f64) = (512, 256, 35.0, 40.0);

/// Whether `degrees` is a sun elevation the built-in sky takes: a finite
/// number in [0, 90] (`--light sky:E:A` and a scene's
/// `sky.sun_elevation` alike).
#[must_use]
pub fn sun_elevation_ok(degrees: f64) -> bool {
    (0.0..=90.0).contains(&degrees)
}

/// Whether `degrees` is a sun azimuth the built-in sky takes: any finite
/// number (0 is −Z).
#[must_use]
pub fn sun_azimuth_ok(degrees: f64) -> bool {
    degrees.is_finite()
}

/// The built-in sky ([`SKY`]'s resolution) with its sun at `elevation` and
/// `azimuth` degrees, times `scale`, rotated by `rotation_y` degrees about
/// +Y: the texels of [`EnvMap::sky`] through [`EnvMap::new`] (which
/// counts the texels clamped, as [`load_envmap`] does), smooth as
/// [`EnvMap::sky`] is ([`EnvMap::smooth`]).
pub fn sky(
    elevation: f64,
    azimuth: f64,
    scale: f64,
    rotation_y: f64,
) -> Result<(EnvMap, usize), lobe::envmap::EnvMapError> {
    let sky = EnvMap::sky(SKY.0, SKY.1, elevation, azimuth);
    let (w, h) = sky.size();
    let texels = (0..h)
        .flat_map(|j| (0..w).map(move |i| (i, j)))
        .map(|(i, j)| sky.texel(i, j))
        .collect();
    EnvMap::new(w, h, texels, scale, rotation_y).map(|(map, clamped)| (map.smooth(), clamped))
}

/// Load `path` (`.hdr`, `.exr`, or the word `sky`) as an environment map
/// with `scale` and a rotation about +Y in degrees. Returns the map and the
/// number of texels whose negative, infinite or NaN channels were clamped
/// to 0 ([`EnvMap::new`]).
pub fn load_envmap(path: &Path, scale: f64, rotation_y: f64) -> Result<(EnvMap, usize), LoadError> {
    let map_err = |source| LoadError::Map {
        path: path.to_path_buf(),
        source,
    };
    if path.as_os_str() == "sky" {
        return sky(SKY.2, SKY.3, scale, rotation_y).map_err(map_err);
    }
    let io_err = |source| LoadError::Io {
        path: path.to_path_buf(),
        source,
    };
    let format_err = |message: String| LoadError::Format {
        path: path.to_path_buf(),
        message,
    };
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("hdr") | Some("pic") => {
            let bytes = std::fs::read(path).map_err(io_err)?;
            let img = image::load_from_memory_with_format(&bytes, image::ImageFormat::Hdr)
                .map_err(|e| format_err(format!("cannot decode: {e}")))?;
            let rgb = img.into_rgb32f();
            let (w, h) = (rgb.width() as usize, rgb.height() as usize);
            let (texels, _) = rgb.as_raw().as_chunks::<3>();
            EnvMap::from_rgb32f(w, h, texels, scale, rotation_y).map_err(map_err)
        }
        Some("exr") => {
            if let Some(name @ ("DWAA" | "DWAB")) =
                exr_compression_of(path).map_err(|e| match e {
                    HeaderError::Io(source) => io_err(source),
                    HeaderError::Format(m) => format_err(m),
                })?
            {
                return Err(format_err(format!(
                    "OpenEXR compression {name} is not supported; re-save the file with ZIP, PIZ, RLE or no compression"
                )));
            }
            let texels = read_exr_rgb(path).map_err(format_err)?;
            EnvMap::from_texel_buffer(texels, scale, rotation_y).map_err(map_err)
        }
        _ => Err(format_err(
            "unknown environment map format: expected a .hdr or .exr file, or `sky`".into(),
        )),
    }
}

/// The most texels [`read_exr_rgb`] decodes: 512 MiB as RGB `f32`, the
/// limit `image`'s reader had (a header can claim any size).
const MAX_EXR_TEXELS: usize = (512 << 20) / 12;

/// The RGB texels of an OpenEXR file's first layer with R, G and B
/// channels, at its largest resolution, row-major from the top: decoded by
/// the `exr` crate straight into the map's storage ([`TexelBuffer`]), as
/// `image`'s reader decodes but without its copy of the file and of the
/// pixels (about 20 MB fewer pages touched for a 1024 × 512 map).
fn read_exr_rgb(path: &Path) -> Result<TexelBuffer, String> {
    match read_exr_rgb_lines(path) {
        Ok(Some(t)) => Ok(t),
        // Another kind of file, or an error the reader below words.
        Ok(None) | Err(_) => read_exr_rgb_pixels(path),
    }
}

/// [`read_exr_rgb`] of a file of one flat layer whose R, G and B channels
/// have a sample per pixel (most maps): the decoded blocks' lines copied a
/// channel at a time, without a call per pixel (a 1024 × 512 map decodes
/// in a third of the time); `None` for any other file. The rows are read
/// in bands on rayon's threads, each band by a reader of its own, which
/// also decompresses its blocks (`exr` reads an uncompressed file's blocks
/// one after the other on one thread, and starts a thread pool of its own
/// to decompress). Every texel comes from the same bytes of the file
/// whatever the number of bands.
fn read_exr_rgb_lines(path: &Path) -> Result<Option<TexelBuffer>, exr::error::Error> {
    read_exr_rgb_lines_in(path, 2 * rayon::current_num_threads())
}

/// [`read_exr_rgb_lines`] in about `bands` bands (at least one block each).
fn read_exr_rgb_lines_in(
    path: &Path,
    bands: usize,
) -> Result<Option<TexelBuffer>, exr::error::Error> {
    use rayon::prelude::*;
    let open = || -> Result<_, exr::error::Error> {
        let file = std::io::BufReader::new(std::fs::File::open(path)?);
        exr::block::read(file, false)
    };
    let reader = open()?;
    let [header] = reader.headers() else {
        return Ok(None);
    };
    let (size, deep) = (header.layer_size, header.deep);
    let list = header.channels.list.clone();
    let find = |name: &str| list.iter().position(|c| c.name == *name);
    let (Some(r), Some(g), Some(b)) = (find("R"), find("G"), find("B")) else {
        return Ok(None);
    };
    if deep
        || list.iter().any(|c| c.sampling != exr::math::Vec2(1, 1))
        || size.area() > MAX_EXR_TEXELS
    {
        return Ok(None);
    }
    // Bands of whole blocks (a block's rows in one band).
    let block_rows = header.max_block_pixel_size().height().max(1);
    let blocks = size.height().div_ceil(block_rows).max(1);
    let per_band = blocks.div_ceil(bands.clamp(1, blocks));
    let mut texels = TexelBuffer::new(size.width(), size.height());
    let rgb = [r, g, b];
    let mut first = Some(reader);
    let bands: Vec<_> = texels
        .bands(per_band * block_rows)
        .map(|band| (band, first.take()))
        .collect();
    bands.into_par_iter().try_for_each(|(band, reader)| {
        let reader = match reader {
            Some(r) => r,
            None => open()?,
        };
        read_band(reader, band, &list, rgb)
    })?;
    Ok(Some(texels))
}

/// The blocks of [`read_exr_rgb_lines`]'s file whose rows are `band`'s,
/// decoded into it (the channels `rgb` of `list` by index).
fn read_band<R: std::io::Read + std::io::Seek + Send>(
    reader: exr::block::reader::Reader<R>,
    mut band: lobe::envmap::TexelBand<'_>,
    list: &[exr::meta::attribute::ChannelDescription],
    rgb: [usize; 3],
) -> Result<(), exr::error::Error> {
    use exr::block::BlockIndex;
    use exr::block::chunk::TileCoordinates;
    use exr::block::reader::ChunksReader;
    use exr::meta::MetaData;
    use exr::meta::attribute::SampleType;
    use exr::prelude::*;
    let rows = band.rows();
    // Each channel's bytes per sample.
    let bytes = |t: SampleType| match t {
        SampleType::F16 => 2,
        SampleType::F32 | SampleType::U32 => 4,
    };
    // The full-resolution level's blocks that start in the band.
    let mine = |_: &MetaData, _: TileCoordinates, i: BlockIndex| {
        i.level == Vec2(0, 0) && rows.contains(&i.pixel_position.y())
    };
    // (Decompressed on the band's thread: the bands are the parallelism,
    // without a thread pool of `exr`'s own per band.)
    reader
        .filter_chunks(false, mine)?
        .decompress_sequential(false, |_, block| {
            let (x0, y0) = (
                block.index.pixel_position.x(),
                block.index.pixel_position.y(),
            );
            let (w, h) = (block.index.pixel_size.x(), block.index.pixel_size.y());
            // A line of the block: each channel's `w` samples in turn.
            let line: usize = list.iter().map(|c| w * bytes(c.sample_type)).sum();
            if block.data.len() != line * h || y0 + h > rows.end || x0 + w > band.width() {
                return Err(exr::error::Error::Invalid("block size".into()));
            }
            for (k, data) in block.data.chunks_exact(line).enumerate() {
                let mut at = 0;
                for (ci, c) in list.iter().enumerate() {
                    let n = w * bytes(c.sample_type);
                    let samples = &data[at..at + n];
                    at += n;
                    let Some(ch) = rgb.iter().position(|&i| i == ci) else {
                        continue;
                    };
                    // Native-endian samples, converted as the pixel reader
                    // converts them (one loop per type, of a constant width).
                    let first = (x0, y0 + k, ch);
                    match c.sample_type {
                        SampleType::F16 => put(&mut band, first, samples, |s: &[u8; 2]| {
                            f16::from_ne_bytes(*s).to_f32()
                        }),
                        SampleType::F32 => put(&mut band, first, samples, |s: &[u8; 4]| {
                            f32::from_ne_bytes(*s)
                        }),
                        SampleType::U32 => put(&mut band, first, samples, |s: &[u8; 4]| {
                            u32::from_ne_bytes(*s) as f32
                        }),
                    }
                }
            }
            Ok(())
        })
}

/// Channel `c` of the texels from `(x0, y)` on: `samples`, `N` bytes each,
/// converted by `convert`.
fn put<const N: usize>(
    band: &mut lobe::envmap::TexelBand<'_>,
    (x0, y, c): (usize, usize, usize),
    samples: &[u8],
    convert: impl Fn(&[u8; N]) -> f32,
) {
    band.set_channel_run(x0, y, c, samples.as_chunks::<N>().0.iter().map(convert));
}

/// [`read_exr_rgb`] through `exr`'s pixel reader: any layout it reads.
fn read_exr_rgb_pixels(path: &Path) -> Result<TexelBuffer, String> {
    use exr::prelude::*;
    // `None`: a layer larger than MAX_EXR_TEXELS (its pixels are skipped).
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .rgb_channels(
            |size, _| {
                (size.area() <= MAX_EXR_TEXELS)
                    .then(|| TexelBuffer::new(size.width(), size.height()))
            },
            |texels: &mut Option<TexelBuffer>, p: Vec2<usize>, (r, g, b): (f32, f32, f32)| {
                if let Some(t) = texels {
                    t.set(p.x(), p.y(), [r, g, b]);
                }
            },
        )
        .first_valid_layer()
        .all_attributes()
        .from_file(path)
        .map_err(|e| {
            format!("cannot decode: {e} (lobe reads the first layer with R, G and B channels)")
        })?;
    let size = image.layer_data.size;
    image.layer_data.channel_data.pixels.ok_or_else(|| {
        format!(
            "the map is {}×{} texels, more than lobe reads ({MAX_EXR_TEXELS}, 512 MiB as RGB f32)",
            size.width(),
            size.height()
        )
    })
}

/// Why the header of an OpenEXR file could not be read.
enum HeaderError {
    Io(std::io::Error),
    Format(String),
}

/// [`exr_compression`] of the file at `path`, from its first 64 KiB (a
/// header is far shorter), or from the whole file when the header goes on
/// beyond them.
fn exr_compression_of(path: &Path) -> Result<Option<&'static str>, HeaderError> {
    use std::io::Read;
    const HEAD: u64 = 1 << 16;
    let mut head = Vec::new();
    std::fs::File::open(path)
        .and_then(|f| f.take(HEAD).read_to_end(&mut head))
        .map_err(HeaderError::Io)?;
    match exr_compression(&head) {
        Err(_) if head.len() as u64 == HEAD => {
            let all = std::fs::read(path).map_err(HeaderError::Io)?;
            exr_compression(&all).map_err(HeaderError::Format)
        }
        r => r.map_err(HeaderError::Format),
    }
}

/// An environment map with the warnings of its loading ([`load_envmap_checked`]).
#[derive(Debug, Clone)]
pub struct LoadedEnvMap {
    pub map: EnvMap,
    /// Texels whose negative, infinite or NaN channels were clamped to 0.
    pub clamped: usize,
    /// What the caller should print, one sentence each, naming the file:
    /// clamped texels, and a map that is not 2:1 (an equirectangular map
    /// spans 360° by 180°, so any other aspect stretches it).
    pub warnings: Vec<String>,
}

/// The warning for a map of `width × height` texels that is not 2:1, if it
/// is not.
#[must_use]
pub fn aspect_warning(path: &Path, width: usize, height: usize) -> Option<String> {
    (width != 2 * height).then(|| {
        format!(
            "{}: the environment map is {width}×{height}, not 2:1; an equirectangular map spans 360°×180°, so it is stretched (is it a cube map, a crop or a light probe?)",
            path.display()
        )
    })
}

/// [`load_envmap`] with its warnings, for the caller to print:
/// [`LoadedEnvMap::warnings`].
pub fn load_envmap_checked(
    path: &Path,
    scale: f64,
    rotation_y: f64,
) -> Result<LoadedEnvMap, LoadError> {
    let (map, clamped) = load_envmap(path, scale, rotation_y)?;
    let mut warnings = Vec::new();
    if clamped > 0 {
        warnings.push(format!(
            "{}: {clamped} texels with negative, infinite or NaN channels were clamped to 0",
            path.display()
        ));
    }
    let (w, h) = map.size();
    warnings.extend(aspect_warning(path, w, h));
    Ok(LoadedEnvMap {
        map,
        clamped,
        warnings,
    })
}

/// The `compression` attribute of an OpenEXR header, by name.
fn exr_compression(bytes: &[u8]) -> Result<Option<&'static str>, String> {
    if bytes.len() < 8 || bytes[..4] != [0x76, 0x2f, 0x31, 0x01] {
        return Err("not an OpenEXR file (bad magic number)".into());
    }
    let mut at = 8;
    let read_str = |at: &mut usize| -> Result<String, String> {
        let end = bytes[*at..]
            .iter()
            .position(|&b| b == 0)
            .ok_or("truncated OpenEXR header")?;
        let s = String::from_utf8_lossy(&bytes[*at..*at + end]).into_owned();
        *at += end + 1;
        Ok(s)
    };
    loop {
        let name = read_str(&mut at)?;
        if name.is_empty() {
            return Ok(None);
        }
        let _type = read_str(&mut at)?;
        let size_bytes = bytes.get(at..at + 4).ok_or("truncated OpenEXR header")?;
        let size = u32::from_le_bytes(size_bytes.try_into().expect("4 bytes")) as usize;
        at += 4;
        let value = bytes.get(at..at + size).ok_or("truncated OpenEXR header")?;
        if name == "compression" {
            let names = [
                "none", "RLE", "ZIPS", "ZIP", "PIZ", "PXR24", "B44", "B44A", "DWAA", "DWAB",
                "HTJ2K",
            ];
            return Ok(value
                .first()
                .and_then(|&c| names.get(c as usize).copied())
                .or(Some("unknown")));
        }
        at += size;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tmp(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("lobe-render-test-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        d.join(name)
    }

    #[test]
    fn hdr_and_exr_round_trip_and_truncated_files_are_errors() {
        let (w, h) = (8u32, 4u32);
        let img =
            image::Rgb32FImage::from_fn(w, h, |x, y| image::Rgb([x as f32 * 0.5, y as f32, 0.25]));
        for ext in ["hdr", "exr"] {
            let p = tmp(&format!("map.{ext}"));
            image::DynamicImage::ImageRgb32F(img.clone())
                .save(&p)
                .unwrap();
            let (m, clamped) = load_envmap(&p, 2.0, 0.0).unwrap();
            assert_eq!(clamped, 0);
            assert_eq!(m.size(), (8, 4));
            let t = m.texel(3, 2);
            assert!(
                (t.x - 3.0).abs() < 0.05 && (t.y - 4.0).abs() < 0.05,
                "{ext}: {t}"
            );
            let bytes = std::fs::read(&p).unwrap();
            let cut = tmp(&format!("cut.{ext}"));
            std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
            let e = load_envmap(&cut, 1.0, 0.0).unwrap_err().to_string();
            assert!(e.contains("cut."), "{e}");
        }
    }

    /// Scanline and tiled OpenEXR files with every lossless compression the
    /// issue names read back to the texels that were written.
    #[test]
    fn exr_scanline_and_tiled_with_each_compression() {
        use exr::prelude::*;
        let (w, h) = (40usize, 20usize);
        let px = |p: Vec2<usize>| (p.x() as f32 * 0.25, p.y() as f32, 0.5f32);
        let blocks = [
            ("scan", Blocks::ScanLines),
            ("tiled", Blocks::Tiles(Vec2(16, 8))),
        ];
        let compressions = [
            ("none", Compression::Uncompressed),
            ("rle", Compression::RLE),
            ("zip", Compression::ZIP16),
            ("zips", Compression::ZIP1),
            ("piz", Compression::PIZ),
        ];
        for (bname, b) in blocks {
            for (cname, c) in compressions {
                let encoding = Encoding {
                    compression: c,
                    blocks: b,
                    line_order: LineOrder::Increasing,
                };
                let layer = Layer::new(
                    (w, h),
                    LayerAttributes::named("rgb"),
                    encoding,
                    SpecificChannels::rgb(px),
                );
                let p = tmp(&format!("{bname}-{cname}.exr"));
                Image::from_layer(layer).write().to_file(&p).unwrap();
                let (m, _) =
                    load_envmap(&p, 1.0, 0.0).unwrap_or_else(|e| panic!("{bname} {cname}: {e}"));
                assert_eq!(m.size(), (w, h), "{bname} {cname}");
                for (i, j) in [(0, 0), (7, 3), (39, 19), (21, 11)] {
                    let t = m.texel(i, j);
                    let e = px(Vec2(i, j));
                    assert!(
                        (t.x - f64::from(e.0)).abs() < 1e-6 && (t.y - f64::from(e.1)).abs() < 1e-6,
                        "{bname} {cname} ({i}, {j}): {t}"
                    );
                }
            }
        }
    }

    /// The line reader gives the pixel reader's texels, bit for bit, for
    /// scanline and tiled files, four compressions and every sample type,
    /// in any number of bands,
    /// with other channels beside R, G and B, lines stored bottom-up, and
    /// the full-resolution level of a mip map; it leaves files of more than
    /// one layer to the pixel reader.
    #[test]
    fn the_line_reader_reads_what_the_pixel_reader_reads() {
        use exr::prelude::*;
        let (w, h) = (37usize, 21usize);
        let value = |c: usize, k: usize| (k * 7 + c * 13) % 29;
        let channel = |name: &str, c: usize, t: &str| {
            let n = w * h;
            let samples = match t {
                "f16" => FlatSamples::F16(
                    (0..n)
                        .map(|k| f16::from_f32(value(c, k) as f32 * 0.37 - 1.0))
                        .collect(),
                ),
                "f32" => {
                    FlatSamples::F32((0..n).map(|k| value(c, k) as f32 * 0.37e3 - 1.0).collect())
                }
                _ => FlatSamples::U32((0..n).map(|k| value(c, k) as u32 * 1000).collect()),
            };
            AnyChannel::new(name, samples)
        };
        let blocks = [Blocks::ScanLines, Blocks::Tiles(Vec2(16, 8))];
        let compressions = [
            Compression::Uncompressed,
            Compression::RLE,
            Compression::ZIP16,
            Compression::PIZ,
        ];
        let mut n = 0;
        for b in blocks {
            for c in compressions {
                for t in ["f16", "f32", "u32"] {
                    let chans = vec![
                        channel("R", 0, t),
                        channel("G", 1, t),
                        channel("B", 2, t),
                        channel("A", 3, "f16"),
                        channel("Z", 4, "f32"),
                    ];
                    let layer = Layer::new(
                        (w, h),
                        LayerAttributes::named("rgb"),
                        Encoding {
                            compression: c,
                            blocks: b,
                            line_order: LineOrder::Decreasing,
                        },
                        AnyChannels::sort(SmallVec::from_vec(chans)),
                    );
                    let p = tmp(&format!("lines-{n}.exr"));
                    n += 1;
                    Image::from_layer(layer).write().to_file(&p).unwrap();
                    let lines = read_exr_rgb_lines(&p).unwrap().expect("one flat layer");
                    let pixels = read_exr_rgb_pixels(&p).unwrap();
                    assert_eq!(lines, pixels, "{b:?} {c:?} {t}");
                    // In 1 to 25 bands (as many as the file has blocks):
                    // the same texels.
                    for bands in [1, 2, 3, 25] {
                        let banded = read_exr_rgb_lines_in(&p, bands).unwrap().unwrap();
                        assert_eq!(banded, pixels, "{b:?} {c:?} {t}, {bands} bands");
                    }
                    // Texel (1, 0)'s red: sample 1 of R, value(0, 1) = 7.
                    let (m, _) = load_envmap(&p, 1.0, 0.0).unwrap();
                    let red = match t {
                        "f16" => f16::from_f32(7.0 * 0.37 - 1.0).to_f32(),
                        "f32" => 7.0 * 0.37e3 - 1.0,
                        _ => 7000.0,
                    };
                    assert_eq!(m.texel(1, 0).x, f64::from(red), "{b:?} {c:?} {t}");
                }
            }
        }
        // A mip-mapped file (tiled): the full-resolution level, the
        // smaller ones different (each level's values offset by its index).
        let levels = exr::meta::mip_map_levels(exr::math::RoundingMode::Down, Vec2(w, h))
            .collect::<Vec<_>>();
        let mip = |name: &str, c: usize| {
            let data = levels
                .iter()
                .map(|(l, size)| {
                    FlatSamples::F32(
                        (0..size.area())
                            .map(|k| value(c, k) as f32 + 100.0 * *l as f32)
                            .collect(),
                    )
                })
                .collect();
            AnyChannel::new(
                name,
                Levels::Mip {
                    rounding_mode: exr::math::RoundingMode::Down,
                    level_data: data,
                },
            )
        };
        let layer = Layer::new(
            (w, h),
            LayerAttributes::named("mip"),
            Encoding {
                compression: Compression::ZIP16,
                blocks: Blocks::Tiles(Vec2(8, 8)),
                line_order: LineOrder::Increasing,
            },
            AnyChannels::sort(SmallVec::from_vec(vec![
                mip("R", 0),
                mip("G", 1),
                mip("B", 2),
            ])),
        );
        let p = tmp("mip.exr");
        Image::from_layer(layer).write().to_file(&p).unwrap();
        let lines = read_exr_rgb_lines(&p).unwrap().expect("one flat layer");
        assert_eq!(lines.size(), (w, h));
        assert_eq!(lines, read_exr_rgb_pixels(&p).unwrap());
        let (m, _) = load_envmap(&p, 1.0, 0.0).unwrap();
        assert_eq!(m.texel(1, 0).x, 7.0);
        // Two layers: the pixel reader's.
        let layer = |name: &str| {
            Layer::new(
                (w, h),
                LayerAttributes::named(name),
                Encoding::UNCOMPRESSED,
                AnyChannels::sort(SmallVec::from_vec(vec![
                    channel("R", 0, "f32"),
                    channel("G", 1, "f32"),
                    channel("B", 2, "f32"),
                ])),
            )
        };
        let p = tmp("two-layers.exr");
        Image::from_layers(
            ImageAttributes::new(IntegerBounds::from_dimensions((w, h))),
            vec![layer("a"), layer("b")],
        )
        .write()
        .to_file(&p)
        .unwrap();
        assert!(read_exr_rgb_lines(&p).unwrap().is_none());
        assert_eq!(read_exr_rgb(&p).unwrap(), read_exr_rgb_pixels(&p).unwrap());
    }

    /// A file without R, G and B channels (luminance only) is an error that
    /// says what lobe reads.
    #[test]
    fn an_exr_without_rgb_channels_is_a_clear_error() {
        use exr::prelude::*;
        let y = AnyChannel::new("Y", FlatSamples::F32(vec![1.0; 8 * 4]));
        let layer = Layer::new(
            (8, 4),
            LayerAttributes::named("y"),
            Encoding::UNCOMPRESSED,
            AnyChannels::sort(SmallVec::from_vec(vec![y])),
        );
        let p = tmp("luminance.exr");
        Image::from_layer(layer).write().to_file(&p).unwrap();
        let e = load_envmap(&p, 1.0, 0.0).unwrap_err().to_string();
        assert!(
            e.contains("luminance.exr") && e.contains("R, G and B channels"),
            "{e}"
        );
    }

    #[test]
    fn dwa_compression_is_named() {
        // A minimal header with compression = DWAB (9).
        let mut b = vec![0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0];
        b.extend_from_slice(b"compression\0compression\0");
        b.extend_from_slice(&1u32.to_le_bytes());
        b.push(9);
        b.push(0);
        let p = tmp("dwab.exr");
        std::fs::write(&p, &b).unwrap();
        let e = load_envmap(&p, 1.0, 0.0).unwrap_err().to_string();
        assert!(e.contains("DWAB") && e.contains("dwab.exr"), "{e}");
    }

    #[test]
    fn missing_files_and_unknown_formats_name_the_path() {
        let e = load_envmap(Path::new("/nonexistent/forest.hdr"), 1.0, 0.0)
            .unwrap_err()
            .to_string();
        assert!(e.contains("/nonexistent/forest.hdr"), "{e}");
        let p = tmp("map.jpg");
        std::fs::write(&p, b"x").unwrap();
        assert!(
            load_envmap(&p, 1.0, 0.0)
                .unwrap_err()
                .to_string()
                .contains("map.jpg")
        );
    }

    #[test]
    fn the_shared_maps_load_when_present() {
        let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/envmaps/forest.hdr");
        if p.exists() {
            let (m, _) = load_envmap(&p, 1.0, 0.0).unwrap();
            assert_eq!(m.size(), (1024, 512));
        }
    }

    #[test]
    fn a_map_that_is_not_two_to_one_is_a_warning() {
        let img = image::Rgb32FImage::from_fn(8, 8, |_, _| image::Rgb([1.0, 1.0, 1.0]));
        let p = tmp("square.HDR");
        img.save_with_format(&p, image::ImageFormat::Hdr).unwrap();
        let loaded = load_envmap_checked(&p, 1.0, 0.0).unwrap();
        assert_eq!(loaded.warnings.len(), 1, "{:?}", loaded.warnings);
        assert!(
            loaded.warnings[0].contains("8×8, not 2:1"),
            "{:?}",
            loaded.warnings
        );
        let img = image::Rgb32FImage::from_fn(8, 4, |_, _| image::Rgb([1.0, 1.0, 1.0]));
        let p = tmp("wide.Exr");
        img.save_with_format(&p, image::ImageFormat::OpenExr)
            .unwrap();
        assert!(
            load_envmap_checked(&p, 1.0, 0.0)
                .unwrap()
                .warnings
                .is_empty()
        );
        let sky = load_envmap_checked(Path::new("sky"), 1.0, 0.0).unwrap();
        assert!(sky.warnings.is_empty());
    }
}
