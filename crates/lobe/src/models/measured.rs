//! Measured BRDFs: MERL `.binary` tables and RGL `.bsdf` files (Dupuy and
//! Jakob 2018), recognised by their content, not their extension.
//!
//! | parameter | range | default | meaning |
//! |---|---|---|---|
//! | `path` | a file (MERL .binary or RGL .bsdf, by content) | required | the table; a relative path is relative to the file that names it (the working directory for inline JSON) |
//! | `interpolation` | `nearest`, `linear` (MERL only) | `nearest` for MERL, as MERL's own reader | MERL lookup: the entry the pair falls in, or trilinear in (√θh, θd, φd); RGL files are always interpolated by their own warps |
//!
//! (This table is [`PARAMS`]; a test checks that they agree.)
//!
//! A table is read once while any material holds it (per file, size,
//! modification time and interpolation), stored as `f32`, and shared by
//! every material that names it: the lobe holds an `Arc` of it, so that
//! cloning a [`Measured`] (and a material) is a reference count, and the
//! table is freed with the last material that holds it (the cache keeps
//! only weak references).
//!
//! * MERL ([`merl`]): RGB per (θh, θd, φd) entry, nearest or trilinear; a
//!   missing entry (negative in the file) reflects nothing.
//! * RGL ([`rgl`]): isotropic files only (an anisotropic file is refused
//!   with an error); RGB or spectral (reduced to RGB when read). `f_r` is
//!   the file's `f cos θi` divided by `cos θi`.
//!
//! Strategies: `uniform`, `cosine`, and `brdf`, the tabulated sampler of
//! [`sampler`] (half-vector cells weighted by `lum(f) cos θi` and the
//! half-vector Jacobian, 10% cosine sampling), built from the table when it
//! is loaded, with an exact pdf; `brdf` is this same sampler for MERL and
//! RGL files alike. RGL files also have `vndf`: Dupuy and Jakob's own
//! scheme, the file's luminance warp then its visible-normal warp
//! ([`rgl::Rgl::sample_warps`], as Mitsuba 3 samples), with its exact pdf
//! ([`rgl::Rgl::pdf_warps`]); a MERL table has no such warps and refuses
//! `vndf`.

use super::{Bxdf, ModelInfo, Param, Range, Value};
use crate::math::Rgb;
use crate::sample::Scattering;
use crate::{BsdfStrategy, Error};
use glam::{DVec2, DVec3};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, OnceLock, Weak};

pub mod merl;
pub mod rgl;
pub mod sampler;

pub use merl::Interpolation;

pub const PATH: Param = Param {
    name: "path",
    range: Range::File,
    note: "",
    default: Value::Text("required"),
    meaning: "the table; a relative path is relative to the file that names it (the working directory for inline JSON)",
};

pub const INTERPOLATION: Param = Param {
    name: "interpolation",
    range: Range::Names("nearest, linear"),
    note: "(MERL only)",
    default: Value::Text("`nearest` for MERL, as MERL's own reader"),
    meaning: "MERL lookup: the entry the pair falls in, or trilinear in (√θh, θd, φd); RGL files are always interpolated by their own warps",
};

/// The keys of a measured material.
pub const PARAMS: &[Param] = &[PATH, INTERPOLATION];

pub const INFO: ModelInfo = ModelInfo {
    name: "measured",
    params: PARAMS,
    #[cfg(feature = "desc")]
    from_desc,
};

#[cfg(feature = "desc")]
fn from_desc(d: &crate::desc::MaterialDesc) -> crate::error::Result<super::Lobes> {
    let Some(path) = d.path.as_deref() else {
        return Err(Error::param(
            "path",
            "missing: type measured needs the file of a MERL (.binary) or RGL (.bsdf) table",
        ));
    };
    let interpolation = match d.interpolation.as_deref() {
        None => None,
        Some("nearest") => Some(Interpolation::Nearest),
        Some("linear") => Some(Interpolation::Linear),
        Some(other) => {
            return Err(Error::UnknownName {
                field: "interpolation".into(),
                value: other.into(),
                expected: "nearest, linear".into(),
            });
        }
    };
    let path = match &d.base {
        Some(base) if Path::new(path).is_relative() => base.join(path),
        _ => PathBuf::from(path),
    };
    let lobe = Measured::load(&path, interpolation)?;
    super::Lobes::with_diffuse(Rgb::ZERO, super::Glossy::Measured(lobe))
}

/// A table as read from a file.
#[derive(Debug, Clone)]
pub enum Table {
    Merl(merl::Merl),
    /// Boxed: an RGL table's fields are large beside MERL's.
    Rgl(Box<rgl::Rgl>),
}

impl Table {
    /// Read a table's bytes, the format recognised by content (`name`
    /// names the file in the error).
    pub fn parse(bytes: &[u8], name: &str) -> crate::error::Result<Table> {
        let r = if rgl::looks_like(bytes) {
            rgl::Rgl::parse(bytes).map(|r| Table::Rgl(Box::new(r)))
        } else if bytes.len() >= 12 && !merl::looks_like(bytes) {
            // Neither: say what the first bytes are, as MERL dimensions.
            merl::Merl::parse(bytes)
                .map(Table::Merl)
                .map_err(|m| format!("not an RGL file (no `tensor_file` header) and not a MERL file: {m}"))
        } else {
            merl::Merl::parse(bytes).map(Table::Merl)
        };
        r.map_err(|m| Error::file(name, m))
    }

    /// The format's name.
    #[must_use]
    pub fn format(&self) -> &'static str {
        match self {
            Table::Merl(_) => "MERL",
            Table::Rgl(_) => "RGL",
        }
    }

    /// `f_r(wo, wi)` without the cosine (both above the horizon).
    #[must_use]
    pub fn eval(&self, wo: DVec3, wi: DVec3, interpolation: Interpolation) -> Rgb {
        match self {
            Table::Merl(m) => m.eval(wo, wi, interpolation),
            Table::Rgl(r) => {
                let v = r.eval_cos(wo, wi) / wi.z;
                v.max(Rgb::ZERO)
            }
        }
    }

    /// Bytes held.
    #[must_use]
    pub fn memory(&self) -> usize {
        match self {
            Table::Merl(m) => m.memory(),
            Table::Rgl(r) => r.memory(),
        }
    }
}

/// A measured table with its sampler, read once and shared.
#[derive(Debug)]
pub struct MeasuredData {
    /// The file it was read from (as given).
    pub path: PathBuf,
    pub table: Table,
    pub interpolation: Interpolation,
    pub sampler: sampler::HalfVectorTable,
    /// Seconds spent reading and checking the file.
    pub read_seconds: f64,
    /// Seconds spent building the sampler's tables.
    pub build_seconds: f64,
}

impl MeasuredData {
    /// Build the sampler for a table.
    #[must_use]
    pub fn new(path: PathBuf, table: Table, interpolation: Interpolation, read_seconds: f64) -> Self {
        let t0 = std::time::Instant::now();
        let sampler = sampler::HalfVectorTable::build(|wo, wi| table.eval(wo, wi, interpolation));
        MeasuredData {
            path,
            table,
            interpolation,
            sampler,
            read_seconds,
            build_seconds: t0.elapsed().as_secs_f64(),
        }
    }
}

/// The measured lobe: a shared table.
#[derive(Clone)]
pub struct Measured {
    pub data: Arc<MeasuredData>,
}

impl std::fmt::Debug for Measured {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "Measured {{ path: {:?}, format: {}, interpolation: {} }}",
            self.data.path,
            self.data.table.format(),
            self.data.interpolation.name()
        )
    }
}

impl PartialEq for Measured {
    /// The same table (the same file, read once).
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.data, &other.data)
    }
}

type CacheKey = (PathBuf, u64, Option<std::time::SystemTime>, Interpolation);

fn cache() -> &'static Mutex<HashMap<CacheKey, Weak<MeasuredData>>> {
    static CACHE: OnceLock<Mutex<HashMap<CacheKey, Weak<MeasuredData>>>> = OnceLock::new();
    CACHE.get_or_init(|| Mutex::new(HashMap::new()))
}

impl Measured {
    /// Read (once while a material holds it) the table at `path`; `interpolation` is for
    /// MERL tables (default nearest) and must be `None` for RGL files.
    pub fn load(path: &Path, interpolation: Option<Interpolation>) -> crate::error::Result<Measured> {
        let name = path.display().to_string();
        let meta = std::fs::metadata(path).map_err(|e| Error::file(&name, format!("cannot read: {e}")))?;
        let canonical = std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf());
        let key_interp = interpolation.unwrap_or(Interpolation::Nearest);
        let key = (canonical, meta.len(), meta.modified().ok(), key_interp);
        // Held while reading: two threads asking for one file read it once.
        let mut map = cache().lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        if let Some(data) = map.get(&key).and_then(Weak::upgrade) {
            return Ok(Measured { data });
        }
        let t0 = std::time::Instant::now();
        let bytes = std::fs::read(path).map_err(|e| Error::file(&name, format!("cannot read: {e}")))?;
        let m = Self::from_bytes_timed(&bytes, path, interpolation, t0)?;
        // Tables no material holds any more leave the cache.
        map.retain(|_, d| d.strong_count() > 0);
        map.insert(key, Arc::downgrade(&m.data));
        Ok(m)
    }

    /// A table from a file's bytes (not cached).
    pub fn from_bytes(
        bytes: &[u8],
        path: &Path,
        interpolation: Option<Interpolation>,
    ) -> crate::error::Result<Measured> {
        Self::from_bytes_timed(bytes, path, interpolation, std::time::Instant::now())
    }

    fn from_bytes_timed(
        bytes: &[u8],
        path: &Path,
        interpolation: Option<Interpolation>,
        t0: std::time::Instant,
    ) -> crate::error::Result<Measured> {
        let table = Table::parse(bytes, &path.display().to_string())?;
        if matches!(table, Table::Rgl(_)) && interpolation.is_some() {
            return Err(Error::param(
                "interpolation",
                format!(
                    "applies to MERL tables only; {} is an RGL file, interpolated by its own warps",
                    path.display()
                ),
            ));
        }
        let read = t0.elapsed().as_secs_f64();
        let data = MeasuredData::new(
            path.to_path_buf(),
            table,
            interpolation.unwrap_or(Interpolation::Nearest),
            read,
        );
        Ok(Measured {
            data: Arc::new(data),
        })
    }

    /// Bytes held by the table and by the sampler.
    #[must_use]
    pub fn memory(&self) -> (usize, usize) {
        (self.data.table.memory(), self.data.sampler.memory())
    }

    /// One line on the table: its file, format, memory, and the times to
    /// read it and to build its sampler (`read gold.bsdf: RGL table, 1.2 MB,
    /// read in 0.01 s; sampler 1.3 MB, built in 0.40 s`).
    #[must_use]
    pub fn summary(&self) -> String {
        let (table, sampler) = self.memory();
        let mb = |b: usize| b as f64 / 1e6;
        format!(
            "read {}: {} table, {:.1} MB, read in {:.2} s; sampler {:.1} MB, built in {:.2} s",
            self.data.path.display(),
            self.data.table.format(),
            mb(table),
            self.data.read_seconds,
            mb(sampler),
            self.data.build_seconds
        )
    }
}

/// A measured table's samplers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MeasuredSampler {
    /// The tabulated half-vector sampler built from the data (`brdf`).
    HalfVector,
    /// An RGL file's own luminance and visible-normal warps (`vndf`).
    Warps,
}

impl Bxdf for Measured {
    type Sampler = MeasuredSampler;

    /// | strategy | sampler | needs |
    /// |---|---|---|
    /// | `brdf` | [`MeasuredSampler::HalfVector`] | |
    /// | `vndf` | [`MeasuredSampler::Warps`] | an RGL file |
    fn sampler(&self, strategy: BsdfStrategy) -> Result<MeasuredSampler, String> {
        match (strategy, &self.data.table) {
            (BsdfStrategy::Brdf, _) => Ok(MeasuredSampler::HalfVector),
            (BsdfStrategy::Vndf, Table::Rgl(_)) => Ok(MeasuredSampler::Warps),
            (BsdfStrategy::Vndf, Table::Merl(_)) => Err(
                "a MERL table has no visible-normal warp (RGL files do); use uniform, cosine or brdf (its tabulated sampler)"
                    .into(),
            ),
            _ => Err(
                "a measured table has no microfacet model; use uniform, cosine, brdf (its tabulated sampler) or, for RGL files, vndf (the file's own warps)"
                    .into(),
            ),
        }
    }

    fn scattering(&self) -> Scattering {
        Scattering::GlossyReflection
    }

    #[inline]
    fn eval(&self, wo: DVec3, wi: DVec3) -> Rgb {
        self.data.table.eval(wo, wi, self.data.interpolation)
    }

    #[inline]
    fn sample(&self, sampler: MeasuredSampler, wo: DVec3, _uc: f64, u: DVec2) -> Option<DVec3> {
        match (sampler, &self.data.table) {
            (MeasuredSampler::Warps, Table::Rgl(r)) => r.sample_warps(wo, u),
            // `Warps` is given for RGL files only (`sampler`).
            (MeasuredSampler::Warps, Table::Merl(_)) => None,
            (MeasuredSampler::HalfVector, _) => self.data.sampler.sample(wo, u),
        }
    }

    #[inline]
    fn pdf(&self, sampler: MeasuredSampler, wo: DVec3, wi: DVec3) -> f64 {
        match (sampler, &self.data.table) {
            (MeasuredSampler::Warps, Table::Rgl(r)) => r.pdf_warps(wo, wi),
            (MeasuredSampler::Warps, Table::Merl(_)) => 0.0,
            (MeasuredSampler::HalfVector, _) => self.data.sampler.pdf(wo, wi),
        }
    }

    fn albedo_hint(&self, wo: DVec3) -> f64 {
        self.data.sampler.albedo(wo)
    }
}
