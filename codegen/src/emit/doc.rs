//! Doc comments of emitted items, which every backend writes the same way.

use proc_macro2::TokenStream;
use quote::quote;

/// `#[doc]` attributes, one a line (paragraphs separated by empty lines).
pub(crate) fn doc_attrs(text: &str) -> TokenStream {
    let lines = text.lines().map(|l| {
        let l = if l.is_empty() {
            String::new()
        } else {
            format!(" {l}")
        };
        quote!(#[doc = #l])
    });
    quote!(#(#lines)*)
}
