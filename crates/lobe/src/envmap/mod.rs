//! Equirectangular environment maps in Mitsuba 3's convention, and their
//! importance sampling.
//!
//! | parameter | meaning |
//! |---|---|
//! | texels | `width × height` linear RGB, row 0 at the top (+Y) |
//! | `scale` | multiplies the radiance |
//! | `rotation_y` | degrees, a rotation of the map about world +Y |
//!
//! World +Y is up. A world direction `d` (after undoing the rotation) maps to
//! `u = atan2(d.x, −d.z) / (2π)` wrapped into [0, 1) and `v = acos(d.y) / π`;
//! texel `(i, j)` covers `u ∈ [i, i+1)/width`, `v ∈ [j, j+1)/height`, and the
//! radiance is constant over it (nearest texel), so that light sampling can be
//! exactly proportional to it. A smooth map ([`EnvMap::smooth`]; the
//! built-in sky, [`EnvMap::sky`]) interpolates its texels bilinearly
//! instead, and its densities follow the interpolation inside each texel
//! too: a texel is picked as below with its luminance replaced by the
//! density's mean over it, then a direction from the density, piecewise
//! bilinear over the texel's quarters (`smooth.rs`).
//!
//! Light sampling picks a texel with probability proportional to its
//! luminance times its solid angle `(2π/width)(cos θ₀ − cos θ₁)` (the sin θ
//! weighting of a latitude-longitude map, integrated exactly over the texel),
//! from a marginal distribution over rows and a conditional one within the
//! row, then a uniform direction inside the texel. The density in solid angle
//! is `lum(texel) / Σ lum·Ω`: proportional to the map's luminance.

// One file per idea, each one using only the files listed above it (no two
// import each other):
//
// | file | holds | uses |
// |---|---|---|
// | `error.rs` | `EnvMapError` | |
// | `distribution.rs` | `Distribution1D` and its borrowed `Tables` | |
// | `texels.rs` | the texels' storage: `Texel`, `TexelBuffer`, `TexelBand` | |
// | `sampler.rs` | the lazy density over the texels: `TexelSampler`, `Columns` | distribution, texels |
// | `smooth.rs` | a smooth map's densities (`Smooth`) and bilinear cells | sampler, texels |
// | `map.rs` | `EnvMap`: building, geometry, the texel search, `eval`, `sample`, `pdf` | error, texels, sampler, smooth |
// | `lookup.rs` | `EnvLookup` and the prefetching lookups, one and many | map, sampler |
// | `tests.rs` | tests of the map as a whole (its sampler's tables, its clamping) | distribution, sampler, map |

mod distribution;
mod error;
mod lookup;
mod map;
mod sampler;
mod smooth;
#[cfg(test)]
mod tests;
mod texels;

pub use distribution::Distribution1D;
pub use error::EnvMapError;
pub use lookup::EnvLookup;
pub use map::EnvMap;
pub use smooth::BilinearCell;
pub use texels::{TexelBand, TexelBuffer};
