//! A block of the batch path as its loops see it: the slices of a block's
//! inputs and outputs, and which outputs `eval_pdf` writes. Shared by the
//! vector loops ([`super::dispatch`]) and the measured tables' loops
//! ([`super::measured`]).

/// Which outputs `eval_pdf` writes: `f` and the pdf, `f` only, the pdf
/// only. The analytic kernels compute both and skip the stores (one
/// instance per kernel, not three: CI's time is compile time); the measured
/// kernels skip the work.
pub(crate) const BOTH: u8 = 0;
pub(crate) const F_ONLY: u8 = 1;
pub(crate) const PDF_ONLY: u8 = 2;

/// Inputs of `sample`: `wo.x, wo.y, wo.z, u1, u2, uc`, all of one length
/// (`uc` is read only where it chooses a lobe).
pub(crate) type SampleIn<'a> = [&'a [f32]; 6];
/// Outputs of `sample`: `wi.xyz, f.rgb, pdf, weight.rgb`, and the mask.
pub(crate) type SampleOut<'a, 'b> = (&'b mut [&'a mut [f32]; 10], &'b mut [u8]);

/// Inputs of `eval_pdf`: `wo.xyz, wi.xyz`.
pub(crate) type EvalIn<'a> = [&'a [f32]; 6];
/// Outputs of `eval_pdf`: `f.rgb, pdf` (the ones the mode does not write
/// may be empty).
pub(crate) type EvalOut<'a, 'b> = &'b mut [&'a mut [f32]; 4];
