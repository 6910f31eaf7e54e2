//! HLSL front-end: preprocess → lex → parse → type-check and emit SPIR-V.

pub mod ast;
pub mod error;
pub mod lex;
pub mod parse;
pub mod pp;
