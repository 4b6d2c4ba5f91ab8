fn main() { println!("{}", dvr_engine::SHADERS.len()); }
