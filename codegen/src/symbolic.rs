//! A small exact symbolic engine over joint sines and cosines and named parameters.
