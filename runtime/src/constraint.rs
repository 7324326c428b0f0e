//! The constraint: Λ = H Ad_gri (3.3), its null-space basis Λ# (3.23)/(3.27), Λ†, the constrained Jacobian J^r_0e (3.15) and J_c (3.33).
