#include "src/io/npy.h"

#include <cctype>
#include <cmath>
#include <cstring>

namespace sft {
namespace {

constexpr char kMagic[] = "\x93NUMPY";
constexpr size_t kMagicSize = 6;

// A cursor over the header dict's text: just enough of Python's literal syntax for the three
// keys numpy writes (strings in single or double quotes, True/False, tuples of integers).
class HeaderParser {
 public:
  explicit HeaderParser(const std::string& text) : text_(text) {}

  void SkipSpace() {
    while (at_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[at_]))) ++at_;
  }
  bool Consume(char c) {
    SkipSpace();
    if (at_ < text_.size() && text_[at_] == c) {
      ++at_;
      return true;
    }
    return false;
  }
  bool String(std::string* out) {
    SkipSpace();
    if (at_ >= text_.size() || (text_[at_] != '\'' && text_[at_] != '"')) return false;
    const char quote = text_[at_++];
    const size_t end = text_.find(quote, at_);
    if (end == std::string::npos) return false;
    *out = text_.substr(at_, end - at_);
    at_ = end + 1;
    return true;
  }
  bool Word(std::string* out) {
    SkipSpace();
    const size_t start = at_;
    while (at_ < text_.size() && std::isalpha(static_cast<unsigned char>(text_[at_]))) ++at_;
    *out = text_.substr(start, at_ - start);
    return !out->empty();
  }
  bool Integer(int64_t* out) {
    SkipSpace();
    const size_t start = at_;
    int64_t value = 0;
    while (at_ < text_.size() && std::isdigit(static_cast<unsigned char>(text_[at_]))) {
      if (value > (kMaxNpyValues * 16)) return false;  // far beyond any accepted size.
      value = 10 * value + (text_[at_++] - '0');
    }
    // numpy may write a Python 2 long ("4L").
    if (at_ > start && at_ < text_.size() && text_[at_] == 'L') ++at_;
    *out = value;
    return at_ > start;
  }
  // "(4, 4)", "(3,)", "()".
  bool Shape(std::vector<int64_t>* shape) {
    if (!Consume('(')) return false;
    shape->clear();
    while (!Consume(')')) {
      int64_t n = 0;
      if (shape->size() >= 32 || !Integer(&n)) return false;
      shape->push_back(n);
      if (!Consume(',')) return Consume(')');
    }
    return true;
  }
  bool AtEnd() {
    SkipSpace();
    return at_ == text_.size();
  }

 private:
  const std::string& text_;
  size_t at_ = 0;
};

Status ParseHeader(const std::string& header, const std::string& name, std::string* descr,
                   bool* fortran_order, std::vector<int64_t>* shape) {
  auto bad = [&name](const std::string& what) { return Status::Error(name + ": header: " + what); };
  HeaderParser p(header);
  if (!p.Consume('{')) return bad("expected a dict starting with '{'");
  bool have_descr = false, have_order = false, have_shape = false;
  while (!p.Consume('}')) {
    std::string key;
    if (!p.String(&key) || !p.Consume(':')) return bad("expected 'key': value");
    if (key == "descr") {
      if (!p.String(descr)) return bad("descr: expected a string such as '<f8'");
      have_descr = true;
    } else if (key == "fortran_order") {
      std::string word;
      if (!p.Word(&word) || (word != "True" && word != "False")) {
        return bad("fortran_order: expected True or False");
      }
      *fortran_order = word == "True";
      have_order = true;
    } else if (key == "shape") {
      if (!p.Shape(shape)) return bad("shape: expected a tuple of integers such as (4, 4)");
      have_shape = true;
    } else {
      return bad("unexpected key '" + key.substr(0, 32) + "'");
    }
    if (!p.Consume(',')) {
      if (!p.Consume('}')) return bad("expected ',' or '}'");
      break;
    }
  }
  if (!p.AtEnd()) return bad("text after the dict");
  if (!have_descr) return bad("no 'descr'");
  if (!have_order) return bad("no 'fortran_order'");
  if (!have_shape) return bad("no 'shape'");
  return Status::Ok();
}

uint64_t ReadLittleEndian(const std::string& bytes, size_t at, int size) {
  uint64_t value = 0;
  for (int i = size - 1; i >= 0; --i) value = (value << 8) | static_cast<uint8_t>(bytes[at + i]);
  return value;
}

}  // namespace

std::string NpyShapeText(const std::vector<int64_t>& shape) {
  std::string text = "(";
  for (size_t i = 0; i < shape.size(); ++i) {
    text += (i ? ", " : "") + std::to_string(shape[i]);
  }
  return text + (shape.size() == 1 ? ",)" : ")");
}

Status ParseNpy(const std::string& bytes, const std::string& name, NpyArray* array) {
  *array = NpyArray();
  if (bytes.size() < kMagicSize + 4 || bytes.compare(0, kMagicSize, kMagic, kMagicSize) != 0) {
    return Status::Error(name + ": not a .npy file (no \\x93NUMPY magic)");
  }
  const int major = static_cast<uint8_t>(bytes[kMagicSize]);
  if (major < 1 || major > 3) {
    return Status::Error(name + ": .npy version " + std::to_string(major) +
                         " is not supported (1 to 3)");
  }
  const int length_size = major == 1 ? 2 : 4;
  const size_t header_start = kMagicSize + 2 + length_size;
  if (bytes.size() < header_start) return Status::Error(name + ": truncated header");
  const uint64_t header_length = ReadLittleEndian(bytes, kMagicSize + 2, length_size);
  if (header_length > bytes.size() - header_start) {
    return Status::Error(name + ": truncated header (" + std::to_string(header_length) +
                         " bytes announced)");
  }
  const std::string header = bytes.substr(header_start, header_length);
  std::string descr;
  bool fortran_order = false;
  std::vector<int64_t> shape;
  SFT_RETURN_IF_ERROR(ParseHeader(header, name, &descr, &fortran_order, &shape));
  int item_size = 0;
  if (descr == "<f8") {
    item_size = 8;
  } else if (descr == "<f4") {
    item_size = 4;
  } else {
    return Status::Error(name + ": descr '" + descr.substr(0, 16) +
                         "' is not supported (need '<f8' or '<f4': little-endian float)");
  }
  int64_t count = 1;
  for (int64_t n : shape) {
    if (n > kMaxNpyValues || (n > 0 && count > kMaxNpyValues / n)) {
      return Status::Error(name + ": shape " + NpyShapeText(shape) + " is larger than sft accepts");
    }
    count *= n;
  }
  if (fortran_order) {
    return Status::Error(name + ": fortran_order True is not supported (need C order)");
  }
  const uint64_t data_start = header_start + header_length;
  const uint64_t expected = static_cast<uint64_t>(count) * item_size;
  if (bytes.size() - data_start != expected) {
    return Status::Error(name + ": shape " + NpyShapeText(shape) + " of " + descr + " needs " +
                         std::to_string(expected) + " data bytes, the file has " +
                         std::to_string(bytes.size() - data_start));
  }
  array->shape = shape;
  array->values.resize(count);
  for (int64_t i = 0; i < count; ++i) {
    const size_t at = data_start + static_cast<size_t>(i) * item_size;
    if (item_size == 8) {
      const uint64_t bits = ReadLittleEndian(bytes, at, 8);
      double v;
      std::memcpy(&v, &bits, 8);
      array->values[i] = v;
    } else {
      const uint32_t bits = static_cast<uint32_t>(ReadLittleEndian(bytes, at, 4));
      float v;
      std::memcpy(&v, &bits, 4);
      array->values[i] = v;
    }
  }
  return Status::Ok();
}

}  // namespace sft
