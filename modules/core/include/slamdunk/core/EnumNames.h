#pragma once
// An enumeration's names in one table, read both ways: INI values, messages and logs then
// spell each value the same way, and a misspelled name can be answered with the choices.
//
// An enumeration gets its table beside its declaration, in namespace slamdunk:
//   SLAMDUNK_ENUM_NAMES(Colour, {{Colour::Red, "red"}, {Colour::Blue, "blue"}});
// An alias (a second name for a value) follows the value's own name in the table.

#include <cctype>
#include <cstddef>
#include <iterator>
#include <optional>
#include <string>
#include <vector>

namespace slamdunk {

template <class Enum>
struct EnumName {
  Enum value;
  const char* name;
};

template <class Enum>
struct EnumNames;

#define SLAMDUNK_ENUM_NAMES(Enum, ...)                     \
  template <>                                              \
  struct EnumNames<Enum> {                                 \
    static constexpr EnumName<Enum> names[] = __VA_ARGS__; \
  }

/// The value named `name` (case does not matter); nothing when no name in the table matches.
template <class Enum>
std::optional<Enum> enumFromName(const std::string& name) {
  auto sameLetters = [&](const char* candidate) {
    std::size_t i = 0;
    for (; candidate[i] != '\0'; ++i)
      if (i >= name.size() || std::tolower(static_cast<unsigned char>(candidate[i])) !=
                                  std::tolower(static_cast<unsigned char>(name[i])))
        return false;
    return i == name.size();
  };
  for (const auto& entry : EnumNames<Enum>::names)
    if (sameLetters(entry.name)) return entry.value;
  return std::nullopt;
}

/// The own names of the values, as "a, b or c" (aliases left out).
template <class Enum>
std::string enumChoices() {
  std::vector<const char*> own;
  const auto& names = EnumNames<Enum>::names;
  for (std::size_t i = 0; i < std::size(names); ++i)
    if (i == 0 || names[i].value != names[i - 1].value) own.push_back(names[i].name);
  std::string choices;
  for (std::size_t i = 0; i < own.size(); ++i) {
    if (i > 0) choices += (i + 1 == own.size()) ? " or " : ", ";
    choices += own[i];
  }
  return choices;
}

/// The own name of `value` ("?" for a value the table does not hold).
template <class Enum, class Table = decltype(EnumNames<Enum>::names)>
const char* toString(Enum value) {
  for (const auto& entry : EnumNames<Enum>::names)
    if (entry.value == value) return entry.name;
  return "?";
}

}  // namespace slamdunk
