//! Bus (being built)
