// The source the libraries' shared precompiled header is built with (cmake/DriftlessFlags.cmake);
// it holds no code.
