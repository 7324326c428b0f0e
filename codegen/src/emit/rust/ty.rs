//! The real type and the runtime path of emitted code: [`Runtime`] (the path through which
//! generated code names the runtime crate) and `Ty`, the token fragments built from both
//! (`T` or `f64`, generics, literals).

use crate::ir::Real;
use proc_macro2::{Literal, TokenStream};
use quote::quote;

/// The default path of the runtime crate in emitted code ([`Runtime`]).
pub const DEFAULT_RUNTIME_PATH: &str = "::trocar";

/// The path through which emitted code names the runtime crate `trocar` (`<T: ::trocar::emitted::Real>`),
/// `::trocar` by default; another path (e.g. `::my_reexport::trocar`) serves a crate that reaches
/// `trocar` through a re-export (prost-build's `prost_path`).
#[derive(Clone, Debug)]
pub struct Runtime {
    path: String,
    tokens: TokenStream,
}

impl Runtime {
    /// The runtime at `path`; `None` when `path` is not a Rust path.
    pub fn new(path: &str) -> Option<Self> {
        let parsed: syn::Path = syn::parse_str(path).ok()?;
        Some(Runtime {
            path: path.to_string(),
            tokens: quote!(#parsed),
        })
    }

    /// The path as given.
    pub fn path(&self) -> &str {
        &self.path
    }

    /// The path as tokens.
    pub fn tokens(&self) -> &TokenStream {
        &self.tokens
    }
}

/// Equal when the paths are written alike.
impl PartialEq for Runtime {
    fn eq(&self, other: &Self) -> bool {
        self.path == other.path
    }
}

impl Eq for Runtime {}

impl Default for Runtime {
    fn default() -> Self {
        Runtime::new(DEFAULT_RUNTIME_PATH).expect("a valid path")
    }
}

/// The real type and the runtime path of emitted code, with the token fragments built from
/// them.
pub(crate) struct Ty {
    pub(crate) real: Real,
    pub(super) runtime: TokenStream,
}

impl Ty {
    pub(crate) fn new(real: Real, runtime: &Runtime) -> Self {
        Ty {
            real,
            runtime: runtime.tokens.clone(),
        }
    }

    /// The runtime crate's path, e.g. `::trocar`.
    pub(crate) fn runtime(&self) -> &TokenStream {
        &self.runtime
    }

    pub(crate) fn t(&self) -> TokenStream {
        match self.real {
            Real::Generic => quote!(T),
            Real::F32 => quote!(f32),
            Real::F64 => quote!(f64),
        }
    }
    /// The generic parameter of a straight-line function: `<T: Arith>` (the part of `Real` that
    /// runs lane by lane, `trocar::emitted::lanes`).
    pub(crate) fn generics(&self) -> TokenStream {
        let rt = &self.runtime;
        match self.real {
            Real::Generic => quote!(<T: #rt::emitted::Arith>),
            _ => quote!(),
        }
    }
    /// The generic parameter of a function that compares or tests a value (`is_finite`):
    /// `<T: Real>`.
    pub(crate) fn real_generics(&self) -> TokenStream {
        let rt = &self.runtime;
        match self.real {
            Real::Generic => quote!(<T: #rt::emitted::Real>),
            _ => quote!(),
        }
    }
    pub(crate) fn args(&self) -> TokenStream {
        match self.real {
            Real::Generic => quote!(<T>),
            _ => quote!(),
        }
    }
    /// The path of the arithmetic functions: `<T as Arith>` in a generic module, `<f64 as Real>`
    /// (or `f32`) in a monomorphic one.
    pub(crate) fn real_path(&self) -> TokenStream {
        let t = self.t();
        let rt = &self.runtime;
        match self.real {
            Real::Generic => quote!(<#t as #rt::emitted::Arith>),
            Real::F32 | Real::F64 => quote!(<#t as #rt::emitted::Real>),
        }
    }
    /// The path of `Real`'s own functions (`is_finite`, `to_f64`): `<T as Real>`.
    pub(crate) fn real_trait_path(&self) -> TokenStream {
        let t = self.t();
        let rt = &self.runtime;
        quote!(<#t as #rt::emitted::Real>)
    }
    pub(crate) fn lit(&self, x: f64) -> TokenStream {
        let r = self.real_path();
        if x == 0.0 {
            return quote!(#r::ZERO);
        }
        if x == 1.0 {
            return quote!(#r::ONE);
        }
        match self.real {
            Real::Generic => {
                let l = Literal::f64_unsuffixed(x);
                quote!(#r::lit(#l))
            }
            Real::F32 | Real::F64 => {
                // The f64's shortest round-trip decimal with the target suffix: rustc rounds the
                // decimal directly to the target type (correct rounding for f32).
                let mut s = format!("{x:?}");
                if !s.contains('.') && !s.contains('e') {
                    s.push_str(".0");
                }
                s.push_str(if self.real == Real::F32 {
                    "_f32"
                } else {
                    "_f64"
                });
                match s.parse::<Literal>() {
                    Ok(l) => quote!(#l),
                    Err(_) => {
                        let l = Literal::f64_unsuffixed(x);
                        quote!(#r::lit(#l))
                    }
                }
            }
        }
    }
}
