//! Code actions and formatting. TO BE WRITTEN.
