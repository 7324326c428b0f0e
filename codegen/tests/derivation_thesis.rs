//! The thesis's printed constrained Jacobians and manipulabilities against the derivation,
//! symbolically.

mod derivation_support;

use derivation_support::*;
use trocar_codegen::derivation::derive;

#[test]
fn explore() {
    for name in ["unidirectional", "bidirectional-zy", "bidirectional-zx"] {
        let d = derive(&preset(name)).unwrap();
        let c = d.constraint.as_ref().unwrap();
        println!("{name}");
        for i in 0..6 {
            let row: Vec<String> = (0..c.m)
                .map(|j| c.jr.get(i, j).display(&d.params).to_string())
                .collect();
            println!("  {}", row.join(" | "));
        }
        println!("  w^2 = {}", c.manipulability.squared.display(&d.params));
    }
}
