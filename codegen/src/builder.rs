//! The build-script API, in the style of prost-build.
