//! The drawing toolkit of every figure the CLI writes (`figures`, the grid
//! of `lobe compare` and `lobe demo`, the fit panels of `lobe plot` and
//! `lobe fit`): the embedded font and text, number labels and ticks, the
//! colours and the colour bar, and writing PNG (or SVG) files.

mod colorbar;
mod error;
mod numbers;
mod output;
mod palette;
mod text;

pub use colorbar::{Orientation, colorbar_extent, draw_colorbar};
pub use error::{DResult, drawing_error};
pub use numbers::{fmt_num, fmt_p, fmt_time, linear_ticks, log_ticks, power_label, sig3};
pub use output::{Figure, append_caption, paint_png, save_figure};
pub use palette::{DIM_TEXT, GRID, LIGHT_GRID, OUTLINE, TEXT, strategy_color, viridis};
pub use text::{draw_title, fit_size, font, put_text, text_style, text_width};
