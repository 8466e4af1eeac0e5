// Numbers of the CSV files (cart_simulate's rows): printf's %.17g text, which reads back to the same
// double, written by std::to_chars in the same format. The text is printf's byte for byte
// (csv_number_test compares two million doubles, NaN and infinities included) at a fraction of its
// cost: printf's number formatting takes about 3 000 instructions a value.
#pragma once

#include <charconv>
#include <string>
#include <system_error>

namespace birkhoff_cart {

/// `value` appended to `text` as std::printf("%.17g", value) writes it.
inline void append_csv_number(std::string& text, double value) {
  char digits[32];  // %.17g needs at most 24 characters ("-1.2345678901234567e-308")
  const std::to_chars_result written =
      std::to_chars(digits, digits + sizeof digits, value, std::chars_format::general, 17);
  if (written.ec == std::errc()) text.append(digits, written.ptr);
}

}  // namespace birkhoff_cart
