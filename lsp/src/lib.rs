pub mod line_index;
