#include "server/encode/image_decoder.hpp"

#include <csetjmp>
#include <cstring>
#include <memory>
#include <string>
#include <utility>

#include <png.h>
#include <turbojpeg.h>

namespace downpour::encode {
namespace {

std::string size_text(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }

// The size a picture must have: exactly width x height (a view's), or, with `up_to`, at most
// that each way and at most max_pixels in all (a model's texture).
struct Expect {
  int width = 0, height = 0;
  bool up_to = false;
  std::size_t max_pixels = 0;
};

// Why a picture of w x h is not as expected; empty if it is.
std::string size_error(const char* kind, int w, int h, Expect e) {
  if (e.up_to) {
    if (w < 1 || h < 1 || w > e.width || h > e.height)
      return std::string("the ") + kind + " is " + size_text(w, h) + ", over the limit of " +
             size_text(e.width, e.height);
    if (static_cast<std::size_t>(w) * static_cast<std::size_t>(h) > e.max_pixels)
      return std::string("the ") + kind + " is " + size_text(w, h) + ", over the " +
             std::to_string(e.max_pixels) + " pixels left to the model";
    return {};
  }
  if (w != e.width || h != e.height)
    return std::string("the ") + kind + " is " + size_text(w, h) + ", the view is " +
           size_text(e.width, e.height);
  return {};
}

BgrxPixels decode_jpeg(std::string_view bytes, Expect expect) {
  std::unique_ptr<void, int (*)(tjhandle)> handle(tjInitDecompress(), &tjDestroy);
  if (!handle) throw std::runtime_error("tjInitDecompress failed");
  const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
  int w = 0, h = 0, subsampling = 0, colourspace = 0;
  if (tjDecompressHeader3(handle.get(), data, bytes.size(), &w, &h, &subsampling, &colourspace) !=
      0) {
    throw DecodeError(std::string("not a JPEG that decodes: ") + tjGetErrorStr2(handle.get()));
  }
  if (const std::string why = size_error("JPEG", w, h, expect); !why.empty())
    throw DecodeError(why);
  BgrxPixels out{w, h, std::vector<std::uint8_t>(static_cast<std::size_t>(w) * h * 4)};
  if (tjDecompress2(handle.get(), data, bytes.size(), out.bgrx.data(), w, 0, h, TJPF_BGRX,
                    TJFLAG_FASTDCT | TJFLAG_BOTTOMUP) != 0 &&
      tjGetErrorCode(handle.get()) == TJERR_FATAL) {
    throw DecodeError(std::string("the JPEG does not decode: ") + tjGetErrorStr2(handle.get()));
  }
  return out;
}

// libpng reading from memory, its errors turned into DecodeError (through longjmp back into read).
struct PngReader {
  std::string_view bytes;
  std::size_t at = 0;
  png_structp png = nullptr;
  png_infop info = nullptr;
  std::string error = "a damaged PNG";
  bool ours = false;  // error is ours, not libpng's

  explicit PngReader(std::string_view b) : bytes(b) {
    png = png_create_read_struct(PNG_LIBPNG_VER_STRING, this, &PngReader::on_error, &on_warning);
    if (!png) throw std::runtime_error("png_create_read_struct failed");
    info = png_create_info_struct(png);
    if (!info) {
      png_destroy_read_struct(&png, nullptr, nullptr);
      throw std::runtime_error("png_create_info_struct failed");
    }
    png_set_read_fn(png, this, &PngReader::on_read);
    // A picture of the view's size is at most a few megapixels: refuse the chunks that say more.
    png_set_user_limits(png, 16384, 16384);
    png_set_chunk_malloc_max(png, 64u << 20);
  }
  ~PngReader() { png_destroy_read_struct(&png, &info, nullptr); }
  PngReader(const PngReader&) = delete;
  PngReader& operator=(const PngReader&) = delete;

  // Back to the caller's setjmp with `error` said whole (not as libpng's).
  [[noreturn]] void fail() {
    ours = true;
    png_longjmp(png, 1);
  }
  // After a longjmp back to the caller's setjmp.
  [[noreturn]] void rethrow() const {
    throw DecodeError(ours ? error : "the PNG does not decode: " + error);
  }
  // Reads the header: the picture's size, which must be width x height; a grey16 one must be one
  // 16-bit grey channel.
  std::pair<int, int> read_header(Expect expect, bool grey16) {
    png_read_info(png, info);
    const int w = static_cast<int>(png_get_image_width(png, info));
    const int h = static_cast<int>(png_get_image_height(png, info));
    if (grey16 && (png_get_color_type(png, info) != PNG_COLOR_TYPE_GRAY ||
                   png_get_bit_depth(png, info) != 16)) {
      error = "not a 16-bit grey PNG";
      fail();
    }
    if (std::string why = size_error("PNG", w, h, expect); !why.empty()) {
      error = std::move(why);
      fail();
    }
    return {w, h};
  }

  static void on_read(png_structp png, png_bytep out, png_size_t n) {
    auto* self = static_cast<PngReader*>(png_get_io_ptr(png));
    if (self->bytes.size() - self->at < n) png_error(png, "the PNG ends early");
    std::memcpy(out, self->bytes.data() + self->at, n);
    self->at += n;
  }
  static void on_error(png_structp png, png_const_charp message) {
    static_cast<PngReader*>(png_get_error_ptr(png))->error = message;
    png_longjmp(png, 1);
  }
  static void on_warning(png_structp, png_const_charp) {}
};

// Reads the rows into `out` (rows bottom-up, `row_bytes` each) once the transforms are set;
// `rows` is the caller's, made before its setjmp (a longjmp skips the destructors of what is made
// after).
void read_rows(PngReader& r, std::vector<png_bytep>& rows, std::uint8_t* out, std::size_t row_bytes,
               int height) {
  rows.resize(height);
  for (int y = 0; y < height; ++y)
    rows[y] = out + static_cast<std::size_t>(height - 1 - y) * row_bytes;
  png_read_image(r.png, rows.data());
  png_read_end(r.png, nullptr);
}

BgrxPixels decode_png_bgrx(std::string_view bytes, Expect expect) {
  PngReader r(bytes);
  BgrxPixels out;
  std::vector<png_bytep> rows;
  // (No object with a destructor is made between the setjmp and a longjmp back to it.)
  if (setjmp(png_jmpbuf(r.png))) r.rethrow();
  const auto [w, h] = r.read_header(expect, false);
  png_set_expand(r.png);  // palette to RGB, grey under 8 bits to 8, tRNS to alpha
  png_set_strip_16(r.png);
  png_set_gray_to_rgb(r.png);
  png_set_bgr(r.png);
  if (!(png_get_color_type(r.png, r.info) & PNG_COLOR_MASK_ALPHA) &&
      !png_get_valid(r.png, r.info, PNG_INFO_tRNS))
    png_set_filler(r.png, 0xff, PNG_FILLER_AFTER);
  png_set_interlace_handling(r.png);
  png_read_update_info(r.png, r.info);
  if (png_get_rowbytes(r.png, r.info) != static_cast<std::size_t>(w) * 4) {
    r.error = "an unexpected PNG layout";
    r.fail();
  }
  out.width = w;
  out.height = h;
  out.bgrx.resize(static_cast<std::size_t>(w) * h * 4);
  read_rows(r, rows, out.bgrx.data(), static_cast<std::size_t>(w) * 4, h);
  return out;
}

}  // namespace

bool is_jpeg(std::string_view b) {
  return b.size() >= 3 && static_cast<std::uint8_t>(b[0]) == 0xff &&
         static_cast<std::uint8_t>(b[1]) == 0xd8 && static_cast<std::uint8_t>(b[2]) == 0xff;
}

bool is_png(std::string_view b) {
  static constexpr char kMagic[8] = {'\x89', 'P', 'N', 'G', '\r', '\n', '\x1a', '\n'};
  return b.size() >= 8 && std::memcmp(b.data(), kMagic, 8) == 0;
}

BgrxPixels decode_bgrx(std::string_view bytes, int width, int height) {
  if (is_jpeg(bytes)) return decode_jpeg(bytes, {width, height});
  if (is_png(bytes)) return decode_png_bgrx(bytes, {width, height});
  throw DecodeError(bytes.empty() ? "empty" : "neither a JPEG nor a PNG");
}

BgrxPixels decode_bgrx_up_to(std::string_view bytes, int max_side, std::size_t max_pixels) {
  const Expect expect{max_side, max_side, true, max_pixels};
  if (is_jpeg(bytes)) return decode_jpeg(bytes, expect);
  if (is_png(bytes)) return decode_png_bgrx(bytes, expect);
  throw DecodeError(bytes.empty() ? "empty" : "neither a JPEG nor a PNG");
}

Grey16Pixels decode_png_grey16(std::string_view bytes, int width, int height) {
  if (!is_png(bytes)) {
    throw DecodeError(is_jpeg(bytes) ? "a JPEG: a depth must be a PNG (JPEG rounds it)"
                                     : "not a PNG");
  }
  PngReader r(bytes);
  Grey16Pixels out;
  std::vector<png_bytep> rows;
  if (setjmp(png_jmpbuf(r.png))) r.rethrow();
  const auto [w, h] = r.read_header({width, height}, true);
  png_set_swap(r.png);  // PNG's big-endian samples to this machine's order
  png_set_interlace_handling(r.png);
  png_read_update_info(r.png, r.info);
  out.width = w;
  out.height = h;
  out.values.resize(static_cast<std::size_t>(w) * h);
  read_rows(r, rows, reinterpret_cast<std::uint8_t*>(out.values.data()),
            static_cast<std::size_t>(w) * 2, h);
  return out;
}

}  // namespace downpour::encode
