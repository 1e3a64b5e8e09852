//! The camera's quadrature error against the 1 nm CIE sum (docs/physics.md, "The camera"):
//! `cargo run --release --example spectral_error`.

use rest_embree::spectrum::{camera, planck, Spectrum};

fn main() {
    println!("| spectrum | largest channel error / largest channel |");
    println!("|---|---|");
    for k in [1625.0, 3250.0, 6500.0, 13000.0, 26000.0] {
        let e = camera::quadrature_error(|nm| planck(nm, k));
        println!("| blackbody {k} K | {:.3}% |", 100.0 * e);
    }
    println!(
        "| the white (D65) | {:.3}% |",
        100.0 * camera::quadrature_error(camera::white)
    );
    for fwhm in [10.0, 20.0, 40.0, 60.0] {
        let worst = (0..=260)
            .map(|i| {
                let line = Spectrum::Line {
                    centre: 420.0 + i as f64,
                    fwhm,
                    scale: 1.0,
                };
                camera::quadrature_error(|nm| line.at(nm))
            })
            .fold(0.0, f64::max);
        println!(
            "| Gaussian line, FWHM {fwhm} nm, worst centre in 420-680 nm | {:.2}% |",
            100.0 * worst
        );
    }
}
