//! Generator of architectural models (placeholder: being written).
