//! Manipulability w = sqrt(|det(J Jᵀ)|) (3.36).
