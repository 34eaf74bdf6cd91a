//! Figures: plots rendered with plotters (being written).
