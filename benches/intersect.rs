//! Single-ray intersection throughput per primitive kind (filled in below).
fn main() {}
