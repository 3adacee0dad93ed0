//! Camera, rasterizer and tone mapping (placeholder: being written).
