//! Mode shapes to VTK legacy files.
