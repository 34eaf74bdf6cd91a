//! Owned columns for the batch kernels: inputs grown a line at a time
//! ([`SampleInputs`], [`DirPairs`]) and outputs sized to them
//! ([`SampleBuffers`], [`EvalPdfBuffers`]), for callers that gather their
//! work before a call (`lobe eval --batch`, tests) instead of holding
//! slices of their own. Reused across blocks, they allocate only when a
//! block is longer than every block before it.

use super::{Dirs, DirsMut, EvalPdfOutput, RgbMut, SampleInput, SampleOutput};

/// The x, y, z columns of a block of directions, as [`Dirs`].
fn dirs(c: &[Vec<f32>; 3]) -> Dirs<'_> {
    Dirs {
        x: &c[0],
        y: &c[1],
        z: &c[2],
    }
}

fn push3(c: &mut [Vec<f32>; 3], v: [f32; 3]) {
    for (col, x) in c.iter_mut().zip(v) {
        col.push(x);
    }
}

/// The inputs of `sample` calls, a sample at a time: `wo` (unit, local
/// frame) and the uniforms `u1`, `u2`, `uc` in `[0, 1)`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SampleInputs {
    pub wo: [Vec<f32>; 3],
    pub u1: Vec<f32>,
    pub u2: Vec<f32>,
    /// The lobe choice; read only where the sampler chooses a lobe
    /// ([`super::BatchSampler::chooses_lobe`]).
    pub uc: Vec<f32>,
}

impl SampleInputs {
    pub fn push(&mut self, wo: [f32; 3], u1: f32, u2: f32, uc: f32) {
        push3(&mut self.wo, wo);
        self.u1.push(u1);
        self.u2.push(u2);
        self.uc.push(uc);
    }

    #[must_use]
    pub fn len(&self) -> usize {
        self.u1.len()
    }

    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.u1.is_empty()
    }

    /// Empty, keeping the allocations.
    pub fn clear(&mut self) {
        for c in self.wo.iter_mut() {
            c.clear();
        }
        self.u1.clear();
        self.u2.clear();
        self.uc.clear();
    }

    /// The columns as one call's input; `uc` passed only when `chooses_lobe`.
    #[must_use]
    pub fn input(&self, chooses_lobe: bool) -> SampleInput<'_> {
        SampleInput {
            wo: dirs(&self.wo),
            u1: &self.u1,
            u2: &self.u2,
            uc: chooses_lobe.then_some(&self.uc[..]),
        }
    }
}

/// `(wo, wi)` pairs for `eval`, `pdf` and `eval_pdf` calls, a pair at a time.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct DirPairs {
    pub wo: [Vec<f32>; 3],
    pub wi: [Vec<f32>; 3],
}

impl DirPairs {
    pub fn push(&mut self, wo: [f32; 3], wi: [f32; 3]) {
        push3(&mut self.wo, wo);
        push3(&mut self.wi, wi);
    }

    #[must_use]
    pub fn len(&self) -> usize {
        self.wo[0].len()
    }

    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.wo[0].is_empty()
    }

    /// Empty, keeping the allocations.
    pub fn clear(&mut self) {
        for c in self.wo.iter_mut().chain(&mut self.wi) {
            c.clear();
        }
    }

    #[must_use]
    pub fn wo(&self) -> Dirs<'_> {
        dirs(&self.wo)
    }

    #[must_use]
    pub fn wi(&self) -> Dirs<'_> {
        dirs(&self.wi)
    }
}

/// Owned output arrays for blocks of `n` samples, allocated once.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SampleBuffers {
    pub wi: [Vec<f32>; 3],
    pub f: [Vec<f32>; 3],
    pub pdf: Vec<f32>,
    pub weight: [Vec<f32>; 3],
    pub valid: Vec<u8>,
}

impl SampleBuffers {
    #[must_use]
    pub fn new(n: usize) -> Self {
        let v = || vec![0.0f32; n];
        SampleBuffers {
            wi: [v(), v(), v()],
            f: [v(), v(), v()],
            pdf: v(),
            weight: [v(), v(), v()],
            valid: vec![0; n],
        }
    }

    /// `n` samples long (the values of a previous block may remain: every
    /// `sample` call writes all of them).
    pub fn resize(&mut self, n: usize) {
        for c in self
            .wi
            .iter_mut()
            .chain(&mut self.f)
            .chain(&mut self.weight)
        {
            c.resize(n, 0.0);
        }
        self.pdf.resize(n, 0.0);
        self.valid.resize(n, 0);
    }

    #[must_use]
    pub fn len(&self) -> usize {
        self.pdf.len()
    }

    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.pdf.is_empty()
    }

    /// The buffers as the output of one `sample` call.
    #[must_use]
    pub fn output(&mut self) -> SampleOutput<'_> {
        let [wx, wy, wz] = &mut self.wi;
        let [fr, fg, fb] = &mut self.f;
        let [r, g, b] = &mut self.weight;
        SampleOutput {
            wi: DirsMut {
                x: wx,
                y: wy,
                z: wz,
            },
            f: RgbMut {
                r: fr,
                g: fg,
                b: fb,
            },
            pdf: &mut self.pdf,
            weight: RgbMut { r, g, b },
            valid: &mut self.valid,
        }
    }

    /// The sampled directions, as the input of `eval_pdf`.
    #[must_use]
    pub fn wi(&self) -> Dirs<'_> {
        Dirs {
            x: &self.wi[0],
            y: &self.wi[1],
            z: &self.wi[2],
        }
    }
}

/// Owned output arrays of `eval_pdf` for blocks of `n` pairs.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct EvalPdfBuffers {
    pub f: [Vec<f32>; 3],
    pub pdf: Vec<f32>,
}

impl EvalPdfBuffers {
    #[must_use]
    pub fn new(n: usize) -> Self {
        let v = || vec![0.0f32; n];
        EvalPdfBuffers {
            f: [v(), v(), v()],
            pdf: v(),
        }
    }

    /// `n` pairs long (the values of a previous block may remain: every
    /// `eval_pdf` call writes all of them).
    pub fn resize(&mut self, n: usize) {
        for c in self.f.iter_mut() {
            c.resize(n, 0.0);
        }
        self.pdf.resize(n, 0.0);
    }

    #[must_use]
    pub fn len(&self) -> usize {
        self.pdf.len()
    }

    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.pdf.is_empty()
    }

    /// The buffers as the output of one `eval_pdf` call.
    #[must_use]
    pub fn output(&mut self) -> EvalPdfOutput<'_> {
        let [r, g, b] = &mut self.f;
        EvalPdfOutput {
            f: RgbMut { r, g, b },
            pdf: &mut self.pdf,
        }
    }
}
