// Placeholder translation unit so the library target exists; replaced as the module grows.
namespace skinlab::experiments {}
