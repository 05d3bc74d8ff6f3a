// Why the targets that create MRPT opengl objects are built without UBSan's alignment check
// (top-level CMakeLists.txt): GCC 12 lays out a base class whose *virtual* base is 32-byte
// aligned at an offset that is a multiple of 8 only (its own members need no more), yet
// -fsanitize=alignment checks calls through that base against alignof(base) = 32. MRPT's
// CSetOfLines, CFrustum, ... (bases CRenderizableShader*, virtual base CRenderizable holding a
// 32-byte aligned CMatrixFixed) hit this in their constructors and destructors. Valid C++, no
// MRPT needed:
//   g++ -std=c++17 -fsanitize=undefined -fno-sanitize-recover=all \
//     scripts/sanitizers/ubsan-virtual-base-alignment.cpp -o /tmp/a && /tmp/a
// prints "constructor call on misaligned address ... for type 'struct C', which requires 32
// byte alignment" and aborts (GCC 12.2, Debian bookworm).
#include <cstdio>
#include <memory>

struct alignas(32) V {
  virtual ~V() = default;
  double x[4] = {};
};
struct B : virtual V {
  int b = 1;
};
struct C : virtual V {
  int c = 2;
  int get() const { return c; }
};
struct D : B, C {};

int main() {
  const auto d = std::make_shared<D>();  // aligned to 32 as it must be
  const C* c = d.get();                  // C sits at offset 16 in D: GCC's own layout
  std::printf("alignof(C) = %zu, D at %p, its C at %p\n", alignof(C), static_cast<void*>(d.get()),
              static_cast<const void*>(c));
  return c->get() == 2 ? 0 : 1;
}
