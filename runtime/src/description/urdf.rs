//! Importing numeric chains from URDF files.
