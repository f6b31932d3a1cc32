// The shim: one counting function per glad entry point (gl_functions.inc, generated from glad's
// gl.h by gl_functions.cmake), each instantiated from one template by its index.
#include "gl_call_counter.h"

#include <glad/gl.h>

#include <array>

namespace lumislab {
namespace {

enum : int {
#define GL_FUNCTION(name) kIndex_##name,
#include "gl_functions.inc"
#undef GL_FUNCTION
  kFunctionCount
};

std::array<void*, kFunctionCount> g_driver{};  // the driver's pointers while installed
std::array<void**, kFunctionCount> g_slot{};   // glad's pointer variables
std::array<const char*, kFunctionCount> g_name{};
std::array<long, kFunctionCount> g_calls{};

template <int Index, typename R, typename... Args>
R GLAD_API_PTR Counting(Args... args) {
  ++g_calls[Index];
  return reinterpret_cast<R(GLAD_API_PTR*)(Args...)>(g_driver[Index])(args...);
}

// Replaces glad's pointer `slot` (when loaded) by Counting<Index>.
template <int Index, typename R, typename... Args>
void Install(R(GLAD_API_PTR*& slot)(Args...), const char* name) {
  g_name[Index] = name;
  g_calls[Index] = 0;
  if (!slot) return;
  g_driver[Index] = reinterpret_cast<void*>(slot);
  g_slot[Index] = reinterpret_cast<void**>(&slot);
  slot = &Counting<Index, R, Args...>;
}

}  // namespace

GlCallCounter::GlCallCounter() {
#define GL_FUNCTION(name) Install<kIndex_##name>(glad_##name, #name);
#include "gl_functions.inc"
#undef GL_FUNCTION
}

GlCallCounter::~GlCallCounter() {
  for (int k = 0; k < kFunctionCount; ++k) {
    if (g_slot[k]) *g_slot[k] = g_driver[k];
    g_slot[k] = nullptr;
    g_driver[k] = nullptr;
  }
}

std::map<std::string, long> GlCallCounter::Counts() const {
  std::map<std::string, long> counts;
  for (int k = 0; k < kFunctionCount; ++k)
    if (g_calls[k] > 0) counts[g_name[k]] = g_calls[k];
  return counts;
}

long GlCallCounter::Total() const {
  long total = 0;
  for (long n : g_calls) total += n;
  return total;
}

void GlCallCounter::Reset() { g_calls.fill(0); }

}  // namespace lumislab
