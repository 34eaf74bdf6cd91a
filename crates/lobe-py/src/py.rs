//! The PyO3 glue: NumPy arrays in, the [`crate::engine`] views, NumPy
//! arrays out; the GIL released while the kernels run.

use crate::engine::{self, BadInput, Engine, In1, In2, Want};
use crate::pool;
use glam::DVec3;
use lobe::{BsdfStrategy, Material};
use ndarray::{Array1, Array2, Ix1, Ix2, ShapeBuilder};
use numpy::{IntoPyArray, PyArrayDyn, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::sync::{Arc, RwLock};

fn value_error(m: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(m.to_string())
}

/// The thread pool of the array calls: `None` is rayon's global pool.
static POOL: RwLock<Option<Arc<rayon::ThreadPool>>> = RwLock::new(None);

fn in_pool<T: Send>(f: impl FnOnce() -> T + Send) -> T {
    let pool = POOL.read().map(|p| p.clone()).unwrap_or(None);
    match pool {
        Some(p) => p.install(f),
        None => f(),
    }
}

/// An input array: f32 or f64 (any other number type becomes f64).
enum Arr<'py> {
    F32(PyReadonlyArrayDyn<'py, f32>),
    F64(PyReadonlyArrayDyn<'py, f64>),
}

fn arr<'py>(obj: &Bound<'py, PyAny>, name: &str) -> PyResult<Arr<'py>> {
    let py = obj.py();
    let np = py.import("numpy")?;
    let a = np
        .call_method1("asarray", (obj,))
        .map_err(|e| value_error(format!("{name}: not an array of numbers ({e})")))?;
    if let Ok(x) = a.cast::<PyArrayDyn<f32>>() {
        return Ok(Arr::F32(
            x.try_readonly()
                .map_err(|e| value_error(format!("{name}: {e}")))?,
        ));
    }
    if let Ok(x) = a.cast::<PyArrayDyn<f64>>() {
        return Ok(Arr::F64(
            x.try_readonly()
                .map_err(|e| value_error(format!("{name}: {e}")))?,
        ));
    }
    let dtype = a.getattr("dtype")?;
    let kind: String = dtype.getattr("kind")?.extract()?;
    if !matches!(kind.as_str(), "b" | "i" | "u" | "f") {
        return Err(value_error(format!(
            "{name}: dtype {} is not a real number type (float32 or float64 expected)",
            dtype.str()?
        )));
    }
    let b = a.call_method1("astype", ("float64",))?;
    let x = b
        .cast_into::<PyArrayDyn<f64>>()
        .map_err(|e| value_error(format!("{name}: {e}")))?;
    Ok(Arr::F64(
        x.try_readonly()
            .map_err(|e| value_error(format!("{name}: {e}")))?,
    ))
}

impl Arr<'_> {
    fn shape(&self) -> Vec<usize> {
        match self {
            Arr::F32(a) => a.shape().to_vec(),
            Arr::F64(a) => a.shape().to_vec(),
        }
    }
}

fn shape_text(s: &[usize]) -> String {
    match s {
        [a] => format!("({a},)"),
        _ => format!(
            "({})",
            s.iter()
                .map(ToString::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// A 2-D view with `cols` columns of `n` rows (any `n` when `None`).
fn view2<'a>(a: &'a Arr<'_>, name: &str, cols: usize, n: Option<usize>) -> PyResult<In2<'a>> {
    let s = a.shape();
    let ok = s.len() == 2 && s[1] == cols && n.is_none_or(|n| s[0] == n);
    if !ok {
        let want = match n {
            Some(n) => format!("({n}, {cols})"),
            None => format!("(N, {cols})"),
        };
        return Err(value_error(format!(
            "{name}: shape {} where {want} is expected",
            shape_text(&s)
        )));
    }
    Ok(match a {
        Arr::F32(x) => In2::F32(x.as_array().into_dimensionality::<Ix2>().expect("2-D")),
        Arr::F64(x) => In2::F64(x.as_array().into_dimensionality::<Ix2>().expect("2-D")),
    })
}

fn view1<'a>(a: &'a Arr<'_>, name: &str, n: usize) -> PyResult<In1<'a>> {
    let s = a.shape();
    if s != [n] {
        return Err(value_error(format!(
            "{name}: shape {} where ({n},) is expected",
            shape_text(&s)
        )));
    }
    Ok(match a {
        Arr::F32(x) => In1::F32(x.as_array().into_dimensionality::<Ix1>().expect("1-D")),
        Arr::F64(x) => In1::F64(x.as_array().into_dimensionality::<Ix1>().expect("1-D")),
    })
}

/// A direction array: `(N, 3)`, or `(3,)` repeated `n` times (owned in `hold`).
enum Dir3 {
    Owned32(Array2<f32>),
    Owned64(Array2<f64>),
}

fn rows_of(a: &Arr<'_>) -> Option<usize> {
    let s = a.shape();
    (s.len() == 2).then(|| s[0])
}

fn dirs<'a>(a: &'a Arr<'_>, name: &str, n: usize, hold: &'a mut Option<Dir3>) -> PyResult<In2<'a>> {
    if a.shape() == [3] {
        *hold = Some(match a {
            Arr::F32(x) => {
                let v = x.as_array();
                Dir3::Owned32(Array2::from_shape_fn((n, 3).f(), |(_, j)| v[j]))
            }
            Arr::F64(x) => {
                let v = x.as_array();
                Dir3::Owned64(Array2::from_shape_fn((n, 3).f(), |(_, j)| v[j]))
            }
        });
        return Ok(match hold.as_ref().expect("set") {
            Dir3::Owned32(x) => In2::F32(x.view()),
            Dir3::Owned64(x) => In2::F64(x.view()),
        });
    }
    view2(a, name, 3, Some(n)).map_err(|_| {
        value_error(format!(
            "{name}: shape {} where ({n}, 3) or (3,) is expected",
            shape_text(&a.shape())
        ))
    })
}

fn bad(e: BadInput) -> PyErr {
    value_error(e.message)
}

fn strategy_of(m: &Material, s: Option<&str>) -> PyResult<BsdfStrategy> {
    match s {
        None => Ok(m.best_bsdf_strategy()),
        Some(name) => {
            let st: BsdfStrategy = name.parse().map_err(value_error)?;
            m.check(st).map_err(value_error)?;
            Ok(st)
        }
    }
}

fn f32_or_64<'py>(
    py: Python<'py>,
    n: usize,
    cols: usize,
    v32: Option<Vec<f32>>,
    v64: Option<Vec<f64>>,
) -> PyResult<Bound<'py, PyAny>> {
    match (v32, v64) {
        (Some(v), _) => result_array(py, v, n, cols),
        (None, Some(v)) => result_array(py, v, n, cols),
        (None, None) => unreachable!("one of the two"),
    }
}

/// Owner of a large result array's memory: when the array dies, its buffer
/// goes back to `crate::pool` for the next call of the same size.
#[pyclass(module = "lobe", name = "_Memory", frozen)]
struct Memory {
    buf: pool::Buffer,
}

impl Drop for Memory {
    fn drop(&mut self) {
        match std::mem::replace(&mut self.buf, pool::Buffer::U8(Vec::new())) {
            pool::Buffer::F32(v) => pool::give(v),
            pool::Buffer::F64(v) => pool::give(v),
            pool::Buffer::U8(v) => pool::give(v),
        }
    }
}

/// `v` as an `(n,)` array (`cols == 1`) or an `(n, cols)` Fortran-ordered
/// one, without a copy; large ones own their memory through [`Memory`].
fn result_array<'py, T: pool::Element + numpy::Element>(
    py: Python<'py>,
    v: Vec<T>,
    n: usize,
    cols: usize,
) -> PyResult<Bound<'py, PyAny>> {
    debug_assert_eq!(v.len(), n * cols);
    if std::mem::size_of_val(v.as_slice()) < pool::MIN_BYTES {
        return Ok(if cols == 1 {
            Array1::from_vec(v).into_pyarray(py).into_any()
        } else {
            Array2::from_shape_vec((n, cols).f(), v)
                .expect("n × cols")
                .into_pyarray(py)
                .into_any()
        });
    }
    let (ptr, len) = (v.as_ptr(), v.len());
    let owner = Bound::new(py, Memory { buf: T::wrap(v) })?.into_any();
    // SAFETY: the vector's heap memory is neither freed nor moved while
    // `owner` lives (it only gives the vector back to the pool when it is
    // dropped), and NumPy keeps `owner` alive as the array's base.
    let data = unsafe { std::slice::from_raw_parts(ptr, len) };
    Ok(unsafe {
        if cols == 1 {
            numpy::PyArray1::borrow_from_array(&ndarray::ArrayView1::from(data), owner).into_any()
        } else {
            let a = ndarray::ArrayView2::from_shape((n, cols).f(), data).expect("n × cols");
            numpy::PyArray2::borrow_from_array(&a, owner).into_any()
        }
    })
}

/// A material: a Lambertian term plus at most one glossy lobe (see
/// `lobe.load_dict`).
///
/// Conventions: local shading frame, +z the normal; `wo` points toward the
/// viewer, `wi` toward the light, both unit vectors away from the surface;
/// `eval` is f_r WITHOUT the cosine; pdfs are solid-angle densities;
/// `weight = f·cos θi / pdf`. Directions are (N, 3) arrays (or one (3,)
/// direction for all), uniforms (N, 2), scalars (N,); float32 or float64,
/// any memory order, any array-like. Results are float32 (the batch SIMD
/// kernels' precision) unless `reference=True`, which runs the scalar f64
/// path and returns float64. (N, 3) results are Fortran-ordered (each
/// component contiguous).
#[pyclass(module = "lobe", name = "Material", frozen)]
pub struct PyMaterial {
    m: Material,
    desc: String,
}

/// The result of `Material.sample`: `wi` (N, 3), `weight` (N, 3, = f·cos θi / pdf, the Monte Carlo weight), `pdf` (N,,
/// solid angle), `valid` (N,) bool. A failed sample (below the horizon) has
/// `valid = False` and zeros elsewhere.
/// Conventions: local frame (+z the normal), wo toward the viewer, wi
/// toward the light, f without the cosine, weight = f·cos θi / pdf.
#[pyclass(module = "lobe", name = "SampleResult", frozen)]
pub struct SampleResult {
    /// The drawn directions wi (N, 3), unit, in the local frame (+z the
    /// normal), pointing toward the light; zero where not valid.
    #[pyo3(get)]
    wi: Py<PyAny>,
    /// The Monte Carlo weights (N, 3) = f·cos θi / pdf (the cosine
    /// included): the estimate of ∫ f cos L dωi is mean(weight · L(wi)).
    #[pyo3(get)]
    weight: Py<PyAny>,
    /// The density (N,) in solid angle with which wi was drawn (the
    /// strategy's pdf, as `Material.pdf` gives it); zero where not valid.
    #[pyo3(get)]
    pdf: Py<PyAny>,
    /// (N,) bool: False for a failed sample (below the horizon), which an
    /// estimator still counts in its N with a zero weight.
    #[pyo3(get)]
    valid: Py<PyAny>,
    /// `valid`'s bytes (uint8, 0/1), for `out=`.
    raw_valid: Py<PyAny>,
}

/// A writeable float32 array of `shape`, Fortran-contiguous, as a slice.
fn out_slice<'py>(
    a: &Bound<'py, PyAny>,
    name: &str,
    shape: &[usize],
) -> PyResult<numpy::PyReadwriteArrayDyn<'py, f32>> {
    let arr = a
        .cast::<PyArrayDyn<f32>>()
        .map_err(|_| value_error(format!("out: {name} is not a float32 array (out= takes the result of a call without reference=True)")))?;
    if arr.shape() != shape
        || !(arr.is_fortran_contiguous() || shape.len() == 1 && arr.is_contiguous())
    {
        return Err(value_error(format!(
            "out: {name} has shape {} (Fortran-contiguous {}), expected {} Fortran-contiguous",
            shape_text(arr.shape()),
            arr.is_fortran_contiguous(),
            shape_text(shape)
        )));
    }
    arr.try_readwrite()
        .map_err(|e| value_error(format!("out: {name}: {e}")))
}

#[pymethods]
impl SampleResult {
    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let n: usize = self.pdf.bind(py).len()?;
        Ok(format!("SampleResult(n={n})"))
    }
}

/// `f` and `pdf` of [`PyMaterial::pair`], each only where wanted.
type Pair<'py> = (Option<Bound<'py, PyAny>>, Option<Bound<'py, PyAny>>);

impl PyMaterial {
    fn pair<'py>(
        &self,
        py: Python<'py>,
        wo: &Bound<'py, PyAny>,
        wi: &Bound<'py, PyAny>,
        strategy: Option<&str>,
        reference: bool,
        want: Want,
    ) -> PyResult<Pair<'py>> {
        let e = match want {
            Want::Eval => Engine::for_eval(&self.m, reference),
            _ => Engine::new(&self.m, strategy_of(&self.m, strategy)?, reference)
                .map_err(value_error)?,
        };
        let (a_wo, a_wi) = (arr(wo, "wo")?, arr(wi, "wi")?);
        let n = rows_of(&a_wi).or(rows_of(&a_wo)).unwrap_or(1);
        let (mut h1, mut h2) = (None, None);
        let v_wo = dirs(&a_wo, "wo", n, &mut h1)?;
        let v_wi = dirs(&a_wi, "wi", n, &mut h2)?;
        let (f, p) = if reference {
            let r = py
                .detach(|| in_pool(|| engine::eval_pdf_scalar::<f64>(&e, &v_wo, &v_wi, want)))
                .map_err(bad)?;
            let engine::EvalPdfOut { f, pdf, .. } = r;
            (
                (want != Want::Pdf)
                    .then(|| f32_or_64(py, n, 3, None, Some(f)))
                    .transpose()?,
                (want != Want::Eval)
                    .then(|| f32_or_64(py, n, 1, None, Some(pdf)))
                    .transpose()?,
            )
        } else {
            let r = py
                .detach(|| in_pool(|| engine::eval_pdf32(&e, &v_wo, &v_wi, want)))
                .map_err(bad)?;
            let engine::EvalPdfOut { f, pdf, .. } = r;
            (
                (want != Want::Pdf)
                    .then(|| f32_or_64(py, n, 3, Some(f), None))
                    .transpose()?,
                (want != Want::Eval)
                    .then(|| f32_or_64(py, n, 1, Some(pdf), None))
                    .transpose()?,
            )
        };
        Ok((f, p))
    }
}

#[pymethods]
impl PyMaterial {
    /// f_r(wo, wi) WITHOUT the cosine, (N, 3); zero unless both directions
    /// are above the horizon (local frame, +z the normal, wo toward the
    /// viewer, wi toward the light; a sample's weight is f·cos θi / pdf).
    /// A zero vector as wi (a failed sample's) gives zero.
    ///
    /// >>> import lobe, numpy as np
    /// >>> m = lobe.load_dict({"type": "lambert", "albedo": 0.5})
    /// >>> f = m.eval([0.0, 0.0, 1.0], np.array([[0.0, 0.6, 0.8]]))
    /// >>> bool(np.allclose(f, 0.5 / np.pi))
    /// True
    #[pyo3(signature = (wo, wi, *, reference = false))]
    fn eval<'py>(
        &self,
        py: Python<'py>,
        wo: &Bound<'py, PyAny>,
        wi: &Bound<'py, PyAny>,
        reference: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        Ok(self
            .pair(py, wo, wi, None, reference, Want::Eval)?
            .0
            .expect("eval"))
    }

    /// The density in solid angle with which `sample(wo, ..., strategy)`
    /// draws wi, (N,); zero below the horizon. `strategy`: one of
    /// `Material.strategies` (default: vndf where it applies, else brdf).
    /// Local frame, +z the normal, wo toward the viewer, wi toward the light;
    /// eval is without the cosine, a sample's weight is f·cos θi / pdf.
    ///
    /// >>> import lobe, numpy as np
    /// >>> m = lobe.load_dict({"type": "lambert"})
    /// >>> bool(m.pdf([0, 0, 1], [[0, 0, 1]], strategy="cosine")[0] == np.float32(1 / np.pi))
    /// True
    #[pyo3(signature = (wo, wi, strategy = None, *, reference = false))]
    fn pdf<'py>(
        &self,
        py: Python<'py>,
        wo: &Bound<'py, PyAny>,
        wi: &Bound<'py, PyAny>,
        strategy: Option<&str>,
        reference: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        Ok(self
            .pair(py, wo, wi, strategy, reference, Want::Pdf)?
            .1
            .expect("pdf"))
    }

    /// `(f, pdf)` in one call: f_r WITHOUT the cosine (N, 3) and the
    /// strategy's solid-angle pdf (N,), sharing their terms. Local frame,
    /// +z the normal, wo toward the viewer, wi toward the light; a sample's
    /// weight is f·cos θi / pdf. `out=(f, pdf)` (float32,
    /// Fortran-contiguous (N, 3) and (N,), e.g. a previous result) writes
    /// into them. The pdf has the bits of `pdf(...)`; f those of `eval`,
    /// except where GGX's vndf and brdf kernels compute it their own way
    /// (as their samples' f): equal to f32 rounding (2e-6 relative).
    ///
    /// >>> import lobe
    /// >>> m = lobe.load_dict({"type": "cook-torrance", "distribution": "ggx", "alpha": 0.2})
    /// >>> f, pdf = m.eval_pdf([0, 0, 1], [[0, 0, 1]], strategy="vndf")
    /// >>> f.shape, pdf.shape, str(f.dtype)
    /// ((1, 3), (1,), 'float32')
    #[pyo3(signature = (wo, wi, strategy = None, *, reference = false, out = None))]
    #[allow(clippy::too_many_arguments)]
    fn eval_pdf<'py>(
        &self,
        py: Python<'py>,
        wo: &Bound<'py, PyAny>,
        wi: &Bound<'py, PyAny>,
        strategy: Option<&str>,
        reference: bool,
        out: Option<(Bound<'py, PyAny>, Bound<'py, PyAny>)>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let Some((fo, po)) = out else {
            let (f, p) = self.pair(py, wo, wi, strategy, reference, Want::Both)?;
            return Ok((f.expect("f"), p.expect("pdf")));
        };
        if reference {
            return Err(value_error(
                "out: not with reference=True (its results are float64)",
            ));
        }
        let e =
            Engine::new(&self.m, strategy_of(&self.m, strategy)?, false).map_err(value_error)?;
        let (a_wo, a_wi) = (arr(wo, "wo")?, arr(wi, "wi")?);
        let n = rows_of(&a_wi).or(rows_of(&a_wo)).unwrap_or(1);
        let (mut h1, mut h2) = (None, None);
        let v_wo = dirs(&a_wo, "wo", n, &mut h1)?;
        let v_wi = dirs(&a_wi, "wi", n, &mut h2)?;
        {
            let mut a_f = out_slice(&fo, "f", &[n, 3])?;
            let mut a_p = out_slice(&po, "pdf", &[n])?;
            let slices = engine::EvalSlices {
                n,
                f: a_f.as_slice_mut().map_err(value_error)?,
                pdf: a_p.as_slice_mut().map_err(value_error)?,
            };
            py.detach(|| in_pool(|| engine::eval_pdf32_into(&e, &v_wo, &v_wi, slices)))
                .map_err(bad)?;
        }
        Ok((fo, po))
    }

    /// Draw wi for each wo with `strategy` (default: vndf where it applies,
    /// else brdf) from the uniforms `u` (N, 2) in [0, 1); `uc` (N,) chooses
    /// the lobe and is required where the material has two (a diffuse term
    /// and a glossy lobe, strategies other than uniform and cosine). Local
    /// frame, +z the normal, wo toward the viewer. Returns a `SampleResult`:
    /// `.wi`, `.weight` (= f·cos θi / pdf), `.pdf` (solid
    /// angle), `.valid`. `out=` a previous result of the same N writes
    /// into its arrays (no new memory) and returns it.
    ///
    /// >>> import lobe, numpy as np
    /// >>> m = lobe.load_dict({"type": "cook-torrance", "distribution": "ggx", "alpha": 0.2})
    /// >>> s = m.sample([0.6, 0.0, 0.8], np.random.default_rng(1).random((1000, 2)))
    /// >>> s.wi.shape, s.weight.shape, s.pdf.shape, str(s.valid.dtype)
    /// ((1000, 3), (1000, 3), (1000,), 'bool')
    /// >>> bool(np.all(s.wi[s.valid, 2] > 0))
    /// True
    #[pyo3(signature = (wo, u, uc = None, strategy = None, *, reference = false, out = None))]
    #[allow(clippy::too_many_arguments)]
    fn sample<'py>(
        &self,
        py: Python<'py>,
        wo: &Bound<'py, PyAny>,
        u: &Bound<'py, PyAny>,
        uc: Option<&Bound<'py, PyAny>>,
        strategy: Option<&str>,
        reference: bool,
        out: Option<Bound<'py, SampleResult>>,
    ) -> PyResult<Py<SampleResult>> {
        let st = strategy_of(&self.m, strategy)?;
        if uc.is_none() && self.m.chooses_lobe(st) {
            return Err(value_error(format!(
                "uc: required: this material has two lobes (a diffuse term kd and a glossy lobe) and strategy `{st}` chooses between them with uc (N,) uniforms"
            )));
        }
        let e = Engine::new(&self.m, st, reference).map_err(value_error)?;
        let a_u = arr(u, "u")?;
        let a_wo = arr(wo, "wo")?;
        let v_u = view2(&a_u, "u", 2, None)?;
        let n = v_u.rows();
        let mut h = None;
        let v_wo = dirs(&a_wo, "wo", n, &mut h)?;
        let a_uc = uc.map(|c| arr(c, "uc")).transpose()?;
        let v_uc = a_uc.as_ref().map(|c| view1(c, "uc", n)).transpose()?;
        if let Some(o) = out {
            if reference {
                return Err(value_error(
                    "out: not with reference=True (its results are float64)",
                ));
            }
            let r = o.get();
            let (wi, weight, pdf, valid) = (
                r.wi.bind(py),
                r.weight.bind(py),
                r.pdf.bind(py),
                r.raw_valid.bind(py),
            );
            let mut a_wi = out_slice(wi, "wi", &[n, 3])?;
            let mut a_w = out_slice(weight, "weight", &[n, 3])?;
            let mut a_p = out_slice(pdf, "pdf", &[n])?;
            let mut a_v = valid
                .cast::<PyArrayDyn<u8>>()
                .map_err(|_| value_error("out: valid"))?
                .try_readwrite()
                .map_err(|e| value_error(format!("out: valid: {e}")))?;
            let slices = engine::SampleSlices {
                n,
                wi: a_wi.as_slice_mut().map_err(value_error)?,
                pdf: a_p.as_slice_mut().map_err(value_error)?,
                weight: a_w.as_slice_mut().map_err(value_error)?,
                valid: a_v.as_slice_mut().map_err(value_error)?,
            };
            if slices.valid.len() != n {
                return Err(value_error(format!(
                    "out: valid has {} values, expected {n}",
                    slices.valid.len()
                )));
            }
            py.detach(|| in_pool(|| engine::sample32_into(&e, &v_wo, &v_u, v_uc.as_ref(), slices)))
                .map_err(bad)?;
            return Ok(o.unbind());
        }
        // The kernels' 0/1 bytes, seen as NumPy bools without a copy.
        let out = |wi, weight, pdf, valid: Vec<u8>| -> PyResult<Py<SampleResult>> {
            let n = valid.len();
            let raw = result_array(py, valid, n, 1)?;
            let r = SampleResult {
                wi,
                weight,
                pdf,
                valid: raw.call_method1("view", ("bool",))?.unbind(),
                raw_valid: raw.into_any().unbind(),
            };
            Py::new(py, r)
        };
        if reference {
            let r = py
                .detach(|| in_pool(|| engine::sample_scalar::<f64>(&e, &v_wo, &v_u, v_uc.as_ref())))
                .map_err(bad)?;
            out(
                f32_or_64(py, n, 3, None, Some(r.wi))?.unbind(),
                f32_or_64(py, n, 3, None, Some(r.weight))?.unbind(),
                f32_or_64(py, n, 1, None, Some(r.pdf))?.unbind(),
                r.valid,
            )
        } else {
            let r = py
                .detach(|| in_pool(|| engine::sample32(&e, &v_wo, &v_u, v_uc.as_ref())))
                .map_err(bad)?;
            out(
                f32_or_64(py, n, 3, Some(r.wi), None)?.unbind(),
                f32_or_64(py, n, 3, Some(r.weight), None)?.unbind(),
                f32_or_64(py, n, 1, Some(r.pdf), None)?.unbind(),
                r.valid,
            )
        }
    }

    /// The strategies that apply to this material (names for `strategy=`).
    /// Conventions: local frame (+z the normal), wo toward the viewer, wi
    /// toward the light, f without the cosine, weight = f·cos θi / pdf.
    #[getter]
    fn strategies(&self) -> Vec<&'static str> {
        self.m
            .strategies()
            .into_iter()
            .map(BsdfStrategy::name)
            .collect()
    }

    /// Whether `strategy` (default: vndf where it applies, else brdf) runs
    /// on the batch SIMD kernels (`True`) or on the scalar f64 path.
    /// Conventions: local frame (+z the normal), wo toward the viewer, wi
    /// toward the light, f without the cosine, weight = f·cos θi / pdf.
    #[pyo3(signature = (strategy = None))]
    fn batched(&self, strategy: Option<&str>) -> PyResult<bool> {
        let st = strategy_of(&self.m, strategy)?;
        Ok(lobe::batch::BatchSampler::new(&self.m, st).is_ok())
    }

    /// A method (call it: `m.chooses_lobe("vndf")`): whether `strategy`
    /// (default: vndf where it applies, else brdf) chooses between the
    /// material's two lobes with `uc`, which `sample` then requires.
    /// Conventions: local frame (+z the normal), wo toward the viewer, wi
    /// toward the light, f without the cosine, weight = f·cos θi / pdf.
    #[pyo3(signature = (strategy = None))]
    fn chooses_lobe(&self, strategy: Option<&str>) -> PyResult<bool> {
        Ok(self.m.chooses_lobe(strategy_of(&self.m, strategy)?))
    }

    /// The model's short name (`lambert`, `phong`, `blinn-phong`,
    /// `cook-torrance`, `measured`, `conductor`, `dielectric`,
    /// `thindielectric`, `roughdielectric`, `plastic`, `roughplastic`).
    /// Conventions: local frame (+z the normal), wo toward the viewer, wi
    /// toward the light, f without the cosine, weight = f·cos θi / pdf.
    #[getter]
    fn model(&self) -> &'static str {
        self.m.model_name()
    }

    /// lobe's description of the material (JSON text, the keys of
    /// `--material`, Mitsuba's plugin names among them).
    /// Conventions: local frame (+z the normal), wo toward the viewer, wi
    /// toward the light, f without the cosine, weight = f·cos θi / pdf.
    #[getter]
    fn description(&self) -> &str {
        &self.desc
    }

    /// The description as TOML text (a material file for `--material
    /// @FILE.toml`, or a scene's `material` table): `MaterialDesc::to_toml`
    /// of `description`, its keys in lobe's order (a Mitsuba colour dict
    /// `{"type": "rgb", "value": [...]}` written as `[r, g, b]`).
    /// Conventions: local frame (+z the normal), wo toward the viewer, wi
    /// toward the light, f without the cosine, weight = f·cos θi / pdf.
    ///
    /// >>> import lobe
    /// >>> print(lobe.load_dict({"type": "roughconductor", "alpha": 0.2}).to_toml().strip())
    /// type = "roughconductor"
    /// alpha = 0.2
    fn to_toml(&self) -> PyResult<String> {
        self.desc_of()?.to_toml().map_err(value_error)
    }

    /// The description as a Python dict literal, for `lobe.load_dict`
    /// (and Mitsuba 3's `mi.load_dict` where the model is Mitsuba's):
    /// `MaterialDesc::to_python` of `description` (`ast.literal_eval`
    /// reads it back).
    /// Conventions: local frame (+z the normal), wo toward the viewer, wi
    /// toward the light, f without the cosine, weight = f·cos θi / pdf.
    ///
    /// >>> import lobe
    /// >>> lobe.load_dict({"type": "roughconductor", "alpha": 0.2}).to_python()
    /// '{"type": "roughconductor", "alpha": 0.2}'
    fn to_python(&self) -> PyResult<String> {
        Ok(self.desc_of()?.to_python())
    }

    fn __repr__(&self) -> String {
        format!("lobe.Material({})", self.desc)
    }
}

impl PyMaterial {
    /// `description` as lobe's `MaterialDesc`.
    fn desc_of(&self) -> PyResult<lobe::MaterialDesc> {
        lobe::MaterialDesc::from_json(&self.desc)
            .map_err(|e| value_error(without_position(&e.to_string())))
    }
}

/// Build a material from JSON text in lobe's `--material` form (Mitsuba's
/// plugin dicts among them); errors name the field.
#[pyfunction]
fn _load_json(text: &str) -> PyResult<PyMaterial> {
    let v: serde_json::Value = serde_json::from_str(text)
        .map_err(|e| value_error(format!("material: invalid JSON: {e}")))?;
    if !v.is_object() {
        return Err(PyTypeError::new_err("material: expected a dict"));
    }
    let desc = v.to_string();
    let m = Material::load(&desc).map_err(|e| value_error(without_position(&e.to_string())))?;
    Ok(PyMaterial { m, desc })
}

/// A parser message without serde's trailing " at line L column C": the
/// position is in the JSON made from the user's dict, which they never see.
fn without_position(m: &str) -> &str {
    if let Some(i) = m.rfind(" at line ") {
        let tail = &m[i + " at line ".len()..];
        if let Some((line, col)) = tail.split_once(" column ")
            && !line.is_empty()
            && line.bytes().all(|b| b.is_ascii_digit())
            && !col.is_empty()
            && col.bytes().all(|b| b.is_ascii_digit())
        {
            return &m[..i];
        }
    }
    m
}

/// Set the number of threads of the array calls (`None`: rayon's default,
/// one per core). The results do not depend on it.
#[pyfunction]
#[pyo3(signature = (n = None))]
fn set_threads(n: Option<usize>) -> PyResult<()> {
    let pool = match n {
        None => None,
        Some(0) => return Err(value_error("set_threads: at least 1 thread")),
        Some(n) => Some(Arc::new(
            rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .map_err(value_error)?,
        )),
    };
    *POOL
        .write()
        .map_err(|_| value_error("thread pool lock poisoned"))? = pool;
    Ok(())
}

/// The number of threads of the array calls.
#[pyfunction]
fn get_threads() -> usize {
    let pool = POOL.read().map(|p| p.clone()).unwrap_or(None);
    pool.map_or_else(rayon::current_num_threads, |p| p.current_num_threads())
}

/// Set the most memory (in bytes) kept for reuse from result arrays that
/// died (default 1 GiB; 0 keeps none). The array calls take a kept buffer
/// of the right size instead of new memory, whose first touch costs page
/// faults: a loop over fresh results then runs about as fast as with
/// `out=`. Only arrays of at least 1 MiB are kept. Results do not depend on
/// it.
///
/// >>> import lobe
/// >>> lobe.set_cache_limit(0); lobe.cache_info()
/// (0, 0)
/// >>> lobe.set_cache_limit(1 << 30)
#[pyfunction]
fn set_cache_limit(nbytes: usize) {
    pool::set_limit(nbytes);
}

/// `(limit, kept)`: the most bytes kept for reuse and the bytes kept now
/// (see `set_cache_limit`).
#[pyfunction]
fn cache_info() -> (usize, usize) {
    pool::limit()
}

/// Free the memory kept for reuse (see `set_cache_limit`).
#[pyfunction]
fn clear_cache() {
    pool::clear();
}

/// The SIMD level of the batch kernels (`avx512`, `avx2`, `scalar`).
#[pyfunction]
fn simd_level() -> PyResult<&'static str> {
    lobe::batch::SimdLevel::from_env()
        .map(|l| l.name())
        .map_err(value_error)
}

fn vec3_of(v: &Bound<'_, PyAny>, name: &str) -> PyResult<DVec3> {
    let a: Vec<f64> = v
        .extract()
        .map_err(|_| value_error(format!("{name}: expected three numbers x, y, z")))?;
    if a.len() != 3 || !a.iter().all(|x| x.is_finite()) {
        return Err(value_error(format!(
            "{name}: expected three finite numbers x, y, z"
        )));
    }
    Ok(DVec3::new(a[0], a[1], a[2]))
}

/// The estimate table as JSON text (`lobe estimate --json`).
#[pyfunction]
#[pyo3(signature = (material, wo, theta, light, normal, tangent, strategies, samples, sequence, seed, replicas, mis_bsdf, mis_samples))]
#[allow(clippy::too_many_arguments)]
fn _estimate_json(
    py: Python<'_>,
    material: &PyMaterial,
    wo: Option<Bound<'_, PyAny>>,
    theta: Option<f64>,
    light: String,
    normal: &Bound<'_, PyAny>,
    tangent: &Bound<'_, PyAny>,
    strategies: Vec<String>,
    samples: usize,
    sequence: String,
    seed: u64,
    replicas: usize,
    mis_bsdf: Option<String>,
    mis_samples: (u32, u32),
) -> PyResult<String> {
    let a = crate::estimate::EstimateArgs {
        wo: wo.map(|w| vec3_of(&w, "wo")).transpose()?,
        theta,
        light,
        normal: vec3_of(normal, "normal")?,
        tangent: vec3_of(tangent, "tangent")?,
        strategies,
        samples,
        sequence,
        seed,
        replicas,
        mis_bsdf,
        mis_samples,
    };
    // (A clone: the material holds its measured table by reference count.)
    let m = material.m.clone();
    py.detach(|| crate::estimate::estimate_json(&m, &a))
        .map_err(value_error)
}

/// Cook-Torrance fitted to a material, as JSON text (`lobe fit --json`
/// without the time): `material`, `error`, `pairs`, `evaluations`.
#[pyfunction]
#[pyo3(signature = (material, distribution, fresnel, anisotropic))]
fn _fit_json(
    py: Python<'_>,
    material: &PyMaterial,
    distribution: &str,
    fresnel: &str,
    anisotropic: bool,
) -> PyResult<String> {
    let distribution = match distribution {
        "ggx" => lobe::Ndf::Ggx,
        "beckmann" => lobe::Ndf::Beckmann,
        other => {
            return Err(value_error(format!(
                "distribution {other:?}: expected ggx or beckmann"
            )));
        }
    };
    let settings = lobe::fit::FitSettings {
        distribution,
        fresnel: fresnel
            .parse()
            .map_err(|e: lobe::Error| value_error(e.to_string()))?,
        anisotropic,
    };
    let m = material.m.clone();
    let fit = py
        .detach(|| lobe::fit::fit(&m, settings))
        .map_err(|e| value_error(e.to_string()))?;
    Ok(fit.report_json(None))
}

/// The white furnace table as JSON text (`lobe furnace --json`).
#[pyfunction]
#[pyo3(signature = (material, thetas, alphas, walks, seed))]
fn _furnace_json(
    py: Python<'_>,
    material: &PyMaterial,
    thetas: Option<Vec<f64>>,
    alphas: Option<Vec<f64>>,
    walks: u64,
    seed: u64,
) -> PyResult<String> {
    use lobe::experiment::furnace::{FurnaceSettings, furnace};
    let desc = lobe::MaterialDesc::from_json(&material.desc)
        .map_err(|e| value_error(without_position(&e.to_string())))?;
    let standard = FurnaceSettings::standard();
    let s = FurnaceSettings {
        thetas: thetas.unwrap_or(standard.thetas),
        alphas: alphas.unwrap_or(standard.alphas),
        walks,
        seed,
    };
    py.detach(|| furnace(&desc, &s, &()).map(|f| f.to_json()))
        .map_err(|e| value_error(e.to_string()))
}

/// `v` as an `(n,)` float64 array.
fn array1(py: Python<'_>, v: Vec<f64>) -> Bound<'_, PyAny> {
    Array1::from_vec(v).into_pyarray(py).into_any()
}

/// `v` as a C-ordered float64 array of `shape`.
fn array_nd<'py>(py: Python<'py>, v: Vec<f64>, shape: &[usize]) -> Bound<'py, PyAny> {
    ndarray::ArrayD::from_shape_vec(ndarray::IxDyn(shape), v)
        .expect("the shape of the values")
        .into_pyarray(py)
        .into_any()
}

/// `_polar`'s `(theta, fcos, pdfs, full_circle)`.
type PolarOut<'py> = (
    Bound<'py, PyAny>,
    Bound<'py, PyAny>,
    Bound<'py, PyDict>,
    bool,
);

/// `_lobe_grid`'s `(theta, phi, values, sphere)`.
type GridOut<'py> = (
    Bound<'py, PyAny>,
    Bound<'py, PyAny>,
    Bound<'py, PyAny>,
    bool,
);

/// The explorer's polar view (`lobe.polar`): `(theta, fcos, pdfs,
/// full_circle)`, `pdfs` a dict of strategy name to array.
#[pyfunction]
#[pyo3(signature = (material, theta_o, phi_o, steps))]
fn _polar<'py>(
    py: Python<'py>,
    material: &PyMaterial,
    theta_o: f64,
    phi_o: f64,
    steps: usize,
) -> PyResult<PolarOut<'py>> {
    let m = &material.m;
    let p = py
        .detach(|| in_pool(|| crate::views::polar(m, theta_o, phi_o, steps)))
        .map_err(value_error)?;
    let pdfs = PyDict::new(py);
    for (name, v) in p.pdfs {
        pdfs.set_item(name, array1(py, v))?;
    }
    Ok((array1(py, p.theta), array1(py, p.fcos), pdfs, p.full_circle))
}

/// The explorer's 3D lobe (`lobe.lobe_grid`): `(theta, phi, values,
/// sphere)`, `values` of shape `(len(theta), len(phi))`.
#[pyfunction]
#[pyo3(signature = (material, theta_o, phi_o, n_theta, n_phi))]
fn _lobe_grid<'py>(
    py: Python<'py>,
    material: &PyMaterial,
    theta_o: f64,
    phi_o: f64,
    n_theta: usize,
    n_phi: usize,
) -> PyResult<GridOut<'py>> {
    let m = &material.m;
    let g = py
        .detach(|| in_pool(|| crate::views::lobe_grid(m, theta_o, phi_o, n_theta, n_phi)))
        .map_err(value_error)?;
    let shape = [g.theta.len(), g.phi.len()];
    Ok((
        array1(py, g.theta),
        array1(py, g.phi),
        array_nd(py, g.values, &shape),
        g.sphere,
    ))
}

/// The explorer's albedo curve (`lobe.albedo_curve`): `(len, 3)` RGB.
#[pyfunction]
#[pyo3(signature = (material, thetas_deg, phi_deg, n))]
fn _albedo_curve<'py>(
    py: Python<'py>,
    material: &PyMaterial,
    thetas_deg: Vec<f64>,
    phi_deg: f64,
    n: usize,
) -> PyResult<Bound<'py, PyAny>> {
    let m = &material.m;
    let a = py
        .detach(|| in_pool(|| crate::views::albedo_curve(m, &thetas_deg, phi_deg, n)))
        .map_err(value_error)?;
    let rows = a.len();
    Ok(array_nd(py, a.into_iter().flatten().collect(), &[rows, 3]))
}

/// The explorer's warp test (`lobe.warp_test`): a dict of `observed`,
/// `expected` (`(grids, res, res)`), `sphere`, `statistic`, `dof`,
/// `p_value` and `message`.
#[pyfunction]
#[pyo3(signature = (material, strategy, theta_o, phi_o, samples, res, seed))]
#[allow(clippy::too_many_arguments)]
fn _warp_test<'py>(
    py: Python<'py>,
    material: &PyMaterial,
    strategy: &str,
    theta_o: f64,
    phi_o: f64,
    samples: usize,
    res: usize,
    seed: Option<u64>,
) -> PyResult<Bound<'py, PyDict>> {
    let m = &material.m;
    let w = py
        .detach(|| in_pool(|| crate::views::warp(m, strategy, theta_o, phi_o, samples, res, seed)))
        .map_err(value_error)?;
    let shape = [if w.sphere { 2 } else { 1 }, w.res, w.res];
    let out = PyDict::new(py);
    out.set_item("observed", array_nd(py, w.observed, &shape))?;
    out.set_item("expected", array_nd(py, w.expected, &shape))?;
    out.set_item("sphere", w.sphere)?;
    out.set_item("statistic", w.statistic)?;
    out.set_item("dof", w.dof)?;
    out.set_item("p_value", w.p_value)?;
    out.set_item("message", w.message)?;
    Ok(out)
}

/// The explorer's weight heat map (`lobe.weight_map`): `(grids, res,
/// res)`, NaN outside the disk or where the strategy never samples.
#[pyfunction]
#[pyo3(signature = (material, strategy, theta_o, phi_o, res))]
fn _weight_map<'py>(
    py: Python<'py>,
    material: &PyMaterial,
    strategy: &str,
    theta_o: f64,
    phi_o: f64,
    res: usize,
) -> PyResult<Bound<'py, PyAny>> {
    let m = &material.m;
    let (v, sphere) = py
        .detach(|| in_pool(|| crate::views::weight_map(m, strategy, theta_o, phi_o, res)))
        .map_err(value_error)?;
    Ok(array_nd(py, v, &[if sphere { 2 } else { 1 }, res, res]))
}

/// Render a scene (TOML text as if read from `path`) to an (H, W, 3)
/// float32 linear image.
/// Run `work` with the GIL released, on a thread of its own, while this
/// thread (Python's main thread, where signal handlers run) checks for
/// signals between waits of at most 50 ms: on Ctrl-C the flag `work` is
/// given is set, `work` is awaited (it stops at its next check), and the
/// signal's exception (`KeyboardInterrupt`) is raised instead of a result.
fn interruptible<T: Send>(
    py: Python<'_>,
    work: impl FnOnce(&std::sync::atomic::AtomicBool) -> T + Send,
) -> PyResult<T> {
    use std::sync::atomic::{AtomicBool, Ordering};
    let cancel = AtomicBool::new(false);
    let (out, interrupted) = py.detach(|| {
        std::thread::scope(|s| {
            let (done, finished) = std::sync::mpsc::channel::<()>();
            let flag = &cancel;
            let worker = s.spawn(move || {
                let out = work(flag);
                let _ = done.send(());
                out
            });
            let mut interrupted = None;
            while let Err(std::sync::mpsc::RecvTimeoutError::Timeout) =
                finished.recv_timeout(std::time::Duration::from_millis(50))
            {
                if interrupted.is_none() {
                    if let Err(e) = Python::attach(|py| py.check_signals()) {
                        cancel.store(true, Ordering::Relaxed);
                        interrupted = Some(e);
                    }
                }
            }
            (worker.join(), interrupted)
        })
    });
    if let Some(e) = interrupted {
        return Err(e);
    }
    out.map_err(|_| pyo3::exceptions::PyRuntimeError::new_err("lobe: the work panicked"))
}

#[pyfunction]
#[pyo3(signature = (text, path, spp, strategy, seed, max_depth, threads, spp_allocation))]
#[allow(clippy::too_many_arguments)]
fn _render<'py>(
    py: Python<'py>,
    text: &str,
    path: &str,
    spp: Option<u64>,
    strategy: Option<&str>,
    seed: Option<u64>,
    max_depth: Option<u32>,
    threads: Option<usize>,
    spp_allocation: Option<&str>,
) -> PyResult<Bound<'py, PyAny>> {
    let mut scene =
        lobe_render::parse_scene(text, std::path::Path::new(path)).map_err(value_error)?;
    let mut opts = scene.settings;
    if let Some(n) = spp {
        if n == 0 {
            return Err(value_error("spp: at least 1 sample per pixel"));
        }
        opts.spp = n;
    }
    if let Some(s) = strategy {
        opts.strategy = s
            .parse()
            .map_err(|e| value_error(format!("strategy: {e}")))?;
    }
    if let Some(s) = seed {
        opts.seed = s;
    }
    if let Some(d) = max_depth {
        if d == 0 {
            return Err(value_error("max_depth: at least 1 (direct lighting)"));
        }
        opts.max_depth = d;
    }
    if threads == Some(0) {
        return Err(value_error("threads: at least 1"));
    }
    if let Some(a) = spp_allocation {
        opts.spp_allocation = a
            .parse()
            .map_err(|e| value_error(format!("spp_allocation: {e}")))?;
    }
    opts.threads = threads;
    scene.settings = opts;
    let (w, h) = (scene.camera.width as usize, scene.camera.height as usize);
    // One pass, as `render` renders it (the same bits), stopped by Ctrl-C.
    let img = interruptible(py, |cancel| {
        lobe_render::integrator::render_until(&scene, &opts, None, 1, cancel, |_| {})
    })?
    .expect("a render that was not interrupted finishes its pass");
    let data = img.to_rgb32f();
    Ok(Array1::from_vec(data)
        .into_shape_with_order((h, w, 3))
        .expect("h × w × 3")
        .into_pyarray(py)
        .into_any())
}

/// JSON text to TOML text (for a scene given as a dict).
#[pyfunction]
fn _json_to_toml(text: &str) -> PyResult<String> {
    let v: serde_json::Value =
        serde_json::from_str(text).map_err(|e| value_error(format!("scene: {e}")))?;
    let t = toml::Value::try_from(v).map_err(|e| value_error(format!("scene: {e}")))?;
    toml::to_string(&t).map_err(|e| value_error(format!("scene: {e}")))
}

/// The harness's uniforms: (N, 3) `(uc, u.x, u.y)` from `Pcg64(seed)`.
#[pyfunction]
fn _chi2_uniforms(py: Python<'_>, seed: u64, samples: usize) -> Bound<'_, PyAny> {
    let u = py.detach(|| crate::chi2::uniforms(seed, samples));
    let flat: Vec<f64> = u.into_iter().flatten().collect();
    Array2::from_shape_vec((samples, 3), flat)
        .expect("n × 3")
        .into_pyarray(py)
        .into_any()
}

/// lobe's chi-square harness on precomputed samples and cell probabilities.
#[pyfunction]
#[pyo3(signature = (n_z, n_phi, min_expected, dirs, valid, probs, errors))]
#[allow(clippy::too_many_arguments)]
fn _chi2_test<'py>(
    py: Python<'py>,
    n_z: usize,
    n_phi: usize,
    min_expected: f64,
    dirs: &Bound<'py, PyAny>,
    valid: &Bound<'py, PyAny>,
    probs: &Bound<'py, PyAny>,
    errors: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyDict>> {
    let d: numpy::PyReadonlyArray2<f64> = dirs.extract()?;
    let v: numpy::PyReadonlyArray1<bool> = valid.extract()?;
    let p: numpy::PyReadonlyArray1<f64> = probs.extract()?;
    let e: numpy::PyReadonlyArray1<f64> = errors.extract()?;
    let (d, v, p, e) = (d.as_array(), v.as_array(), p.as_array(), e.as_array());
    if d.ncols() != 3 || d.nrows() != v.len() || p.len() != n_z * n_phi || e.len() != p.len() {
        return Err(value_error("chi2: inconsistent array shapes"));
    }
    let samples: Vec<Option<DVec3>> = (0..d.nrows())
        .map(|i| v[i].then(|| DVec3::new(d[[i, 0]], d[[i, 1]], d[[i, 2]])))
        .collect();
    let (p, e) = (p.to_vec(), e.to_vec());
    let r = py.detach(|| crate::chi2::test_cells(n_z, n_phi, min_expected, &samples, &p, &e));
    let out = PyDict::new(py);
    out.set_item("statistic", r.statistic)?;
    out.set_item("dof", r.dof)?;
    out.set_item("p_value", r.p_value)?;
    out.set_item(
        "observed",
        Array2::from_shape_vec((n_z, n_phi), r.observed)
            .expect("cells")
            .into_pyarray(py),
    )?;
    out.set_item(
        "expected",
        Array2::from_shape_vec((n_z, n_phi), r.expected)
            .expect("cells")
            .into_pyarray(py),
    )?;
    out.set_item("lost_observed", r.lost_observed)?;
    out.set_item("lost_expected", r.lost_expected)?;
    out.set_item("pdf_integral", r.pdf_integral)?;
    out.set_item("message", r.message)?;
    Ok(out)
}

/// Šidák-corrected level of each of `tests` tests for a family-wise `alpha`.
#[pyfunction]
fn sidak(alpha: f64, tests: usize) -> f64 {
    lobe::stats::chi2::sidak(alpha, tests)
}

#[pymodule]
fn _lobe(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyMaterial>()?;
    m.add_class::<SampleResult>()?;
    m.add_function(wrap_pyfunction!(_load_json, m)?)?;
    m.add_function(wrap_pyfunction!(set_threads, m)?)?;
    m.add_function(wrap_pyfunction!(get_threads, m)?)?;
    m.add_function(wrap_pyfunction!(simd_level, m)?)?;
    m.add_function(wrap_pyfunction!(set_cache_limit, m)?)?;
    m.add_function(wrap_pyfunction!(cache_info, m)?)?;
    m.add_function(wrap_pyfunction!(clear_cache, m)?)?;
    m.add_function(wrap_pyfunction!(_estimate_json, m)?)?;
    m.add_function(wrap_pyfunction!(_furnace_json, m)?)?;
    m.add_function(wrap_pyfunction!(_fit_json, m)?)?;
    m.add_function(wrap_pyfunction!(_render, m)?)?;
    m.add_function(wrap_pyfunction!(_polar, m)?)?;
    m.add_function(wrap_pyfunction!(_lobe_grid, m)?)?;
    m.add_function(wrap_pyfunction!(_albedo_curve, m)?)?;
    m.add_function(wrap_pyfunction!(_warp_test, m)?)?;
    m.add_function(wrap_pyfunction!(_weight_map, m)?)?;
    m.add_function(wrap_pyfunction!(_json_to_toml, m)?)?;
    m.add_function(wrap_pyfunction!(_chi2_uniforms, m)?)?;
    m.add_function(wrap_pyfunction!(_chi2_test, m)?)?;
    m.add_function(wrap_pyfunction!(sidak, m)?)?;
    m.add("BLOCK", engine::BLOCK)?;
    // The package's version (`lobe.__version__`): the workspace's.
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
