use render::{Camera, Lighting, Material, Mesh, Mode, Scene, Settings, metrics};
fn main() {
    let name = std::env::args().nth(1).unwrap_or("chrome".into());
    let env = std::env::args().nth(2).unwrap_or("quarry_01_1k".into());
    let table = merl::read_file(std::path::Path::new(&format!("target/merl/{name}.binary"))).unwrap();
    let map = envmap::load(std::path::Path::new(&format!("../shared/data/env/{env}.hdr"))).unwrap();
    let lighting = Lighting { mips: envmap::MipChain::new(&map), layers: vec![], exponents: vec![] };
    let scene = Scene { mesh: Mesh::sphere(1.0, 128, 64), camera: Camera::default(), width: 128, height: 128 };
    for (slices, vectors, seed) in [(90usize, 128usize, 0u64), (90, 128, 1), (90, 128, 2)] {
        let config = importance::Config { n_theta_o: slices, n_vectors: vectors, seed, ..Default::default() };
        let tables = importance::build(&table, &config).unwrap();
        let samples = bake::stage::importance::sample_set(&tables);
        let material = Material { table: table.clone(), samples, view_layers: vec![0] };
        let frames = render::frames_to_exhaust(vectors, 256, 256);
        let img = render::render(&scene, &material, &lighting, &Settings { mode: Mode::Reference, spp: 256, frames, seed: 0 }).unwrap();
        println!("{name} {env} slices {slices} vectors {vectors} seed {seed}: mean luminance {:.6}", metrics::mean_luminance(&img));
        if seed == 0 {
            let conv = render::converged::converged(&scene, &material, &lighting, 4096, 9).unwrap();
            println!("  converged 4096 seed 9: {:.6}", metrics::mean_luminance(&conv));
        }
    }
}
