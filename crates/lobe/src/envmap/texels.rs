//! A map's texels in `f32` ([`Texel`]), and their storage filled by a
//! decoder, texel by texel or a band of rows at a time ([`TexelBuffer`],
//! [`TexelBand`]).

use crate::math::{Rgb, luminance};

/// One texel's radiance (before `scale`), in `f32` as map files hold it
/// (an `.exr`'s half or float, an `.hdr`'s RGBE: no rounding), padded to
/// 16 bytes so that none straddles a cache line.
#[derive(Debug, Clone, Copy, PartialEq)]
#[repr(C, align(16))]
pub(super) struct Texel {
    pub(super) rgb: [f32; 3],
}

impl Texel {
    #[inline]
    pub(super) fn rgb(self) -> Rgb {
        Rgb::new(
            f64::from(self.rgb[0]),
            f64::from(self.rgb[1]),
            f64::from(self.rgb[2]),
        )
    }

    /// The luminance, in `f64` from the `f64` radiance: the same bits
    /// wherever it is computed (the densities' build and every lookup).
    #[inline]
    pub(super) fn lum(self) -> f64 {
        luminance(self.rgb())
    }
}

/// The texels of a map being decoded, in the map's own storage, zero until
/// set: a decoder writes each texel where it belongs ([`TexelBuffer::set`],
/// or a line's channel at a time into a band of rows,
/// [`TexelBuffer::bands`]) and [`EnvMap::from_texel_buffer`](super::EnvMap::from_texel_buffer) takes the
/// storage as it is.
#[derive(Debug, Clone, PartialEq)]
pub struct TexelBuffer {
    pub(super) width: usize,
    pub(super) height: usize,
    pub(super) texels: Vec<Texel>,
}

impl TexelBuffer {
    /// `width × height` black texels.
    ///
    /// # Panics
    /// If `width × height` overflows `usize`.
    #[must_use]
    pub fn new(width: usize, height: usize) -> Self {
        let n = width
            .checked_mul(height)
            .expect("TexelBuffer: width × height overflows");
        let black = Texel { rgb: [0.0; 3] };
        // Written on rayon's threads when there are: the first touch of
        // each page of a large map (a page fault each, 2048 for 1024 × 512)
        // shared out.
        #[cfg(feature = "parallel")]
        let texels = {
            use rayon::prelude::*;
            let mut t = Vec::with_capacity(n);
            t.par_extend(rayon::iter::repeat_n(black, n));
            t
        };
        #[cfg(not(feature = "parallel"))]
        let texels = vec![black; n];
        TexelBuffer {
            width,
            height,
            texels,
        }
    }

    /// Set texel `(i, j)` (column, row from the top) to `rgb` (before the
    /// map's scale; clamped as [`EnvMap::new`](super::EnvMap::new) clamps when the map is built).
    ///
    /// # Panics
    /// If `(i, j)` is outside the buffer.
    #[inline]
    pub fn set(&mut self, i: usize, j: usize, rgb: [f32; 3]) {
        assert!(
            i < self.width && j < self.height,
            "TexelBuffer::set: ({i}, {j}) outside {}×{}",
            self.width,
            self.height
        );
        self.texels[j * self.width + i] = Texel { rgb };
    }

    /// The buffer cut into bands of `rows` rows each from the top (the last
    /// one shorter when `rows` does not divide the height), each one borrowed
    /// on its own: a decoder's threads can set a band each
    /// ([`TexelBand::set_channel_run`]). None for a buffer without texels.
    ///
    /// # Panics
    /// If `rows` is 0.
    pub fn bands(&mut self, rows: usize) -> impl Iterator<Item = TexelBand<'_>> {
        assert!(rows > 0, "TexelBuffer::bands: bands of 0 rows");
        let width = self.width;
        // (`max(1)`: a buffer of width 0 has no texels, so no chunk.)
        self.texels
            .chunks_mut(rows.saturating_mul(width).max(1))
            .enumerate()
            .map(move |(k, texels)| TexelBand {
                width,
                first_row: k * rows,
                rows: texels.len() / width,
                texels,
            })
    }

    /// `(width, height)`.
    #[must_use]
    pub fn size(&self) -> (usize, usize) {
        (self.width, self.height)
    }
}

/// Rows of a [`TexelBuffer`], borrowed to be set ([`TexelBuffer::bands`]).
#[derive(Debug)]
pub struct TexelBand<'a> {
    width: usize,
    first_row: usize,
    rows: usize,
    texels: &'a mut [Texel],
}

impl TexelBand<'_> {
    /// The buffer's rows the band holds.
    #[must_use]
    pub fn rows(&self) -> std::ops::Range<usize> {
        self.first_row..self.first_row + self.rows
    }

    /// The buffer's width in texels.
    #[must_use]
    pub fn width(&self) -> usize {
        self.width
    }

    /// Set channel `c` (0 red, 1 green, 2 blue) of the run of texels
    /// starting at `(i0, j)` (`j` counted from the top of the buffer):
    /// `values[k]` to texel `(i0 + k, j)` (a decoder's line of one channel,
    /// as [`TexelBuffer::set`] sets texels). A whole buffer is one band
    /// (`bands(height)`).
    ///
    /// # Panics
    /// If the run leaves row `j` or the band, or `c > 2`.
    #[inline]
    pub fn set_channel_run(
        &mut self,
        i0: usize,
        j: usize,
        c: usize,
        values: impl ExactSizeIterator<Item = f32>,
    ) {
        let n = values.len();
        assert!(
            c < 3 && self.rows().contains(&j) && i0.checked_add(n).is_some_and(|e| e <= self.width),
            "TexelBand::set_channel_run: channel {c}, {n} texels from ({i0}, {j}) outside rows {:?} of width {}",
            self.rows(),
            self.width
        );
        let start = (j - self.first_row) * self.width + i0;
        for (t, v) in self.texels[start..start + n].iter_mut().zip(values) {
            t.rgb[c] = v;
        }
    }
}
