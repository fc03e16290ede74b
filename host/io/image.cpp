#include "io/image.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include <ImfArray.h>
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfIO.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <stb_image_write.h>

#include "util/error.h"
#include "util/files.h"
#include "util/input_file.h"

namespace pr {

namespace fs = std::filesystem;

namespace {

// An OpenEXR input stream over a file's bytes, read first through the one opener.
class MemoryIStream : public Imf::IStream {
 public:
  MemoryIStream(const std::string& name, std::vector<uint8_t> bytes)
      : Imf::IStream(name.c_str()), bytes_(std::move(bytes)) {}
  bool isMemoryMapped() const override { return true; }
  char* readMemoryMapped(int n) override { return take(n); }
  bool read(char c[], int n) override {
    std::memcpy(c, take(n), size_t(n));
    return pos_ < bytes_.size();
  }
  uint64_t tellg() override { return pos_; }
  void seekg(uint64_t pos) override { pos_ = pos; }
  void clear() override {}

 private:
  char* take(int n) {
    if (n < 0 || pos_ > bytes_.size() || uint64_t(n) > bytes_.size() - pos_)
      throw std::runtime_error("unexpected end of file");
    char* at = reinterpret_cast<char*>(bytes_.data() + pos_);
    pos_ += uint64_t(n);
    return at;
  }
  std::vector<uint8_t> bytes_;
  uint64_t pos_ = 0;
};

// An OpenEXR output stream into a string.
class MemoryOStream : public Imf::OStream {
 public:
  MemoryOStream() : Imf::OStream("memory") {}
  void write(const char c[], int n) override {
    if (pos_ + n > bytes_.size()) bytes_.resize(pos_ + n);
    std::memcpy(&bytes_[pos_], c, n);
    pos_ += n;
  }
  uint64_t tellp() override { return pos_; }
  void seekp(uint64_t pos) override { pos_ = pos; }
  const std::string& bytes() const { return bytes_; }

 private:
  std::string bytes_;
  size_t pos_ = 0;
};

float srgbEncode(float v) {
  v = std::clamp(v, 0.0f, 1.0f);
  return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
}

}  // namespace

void writeExr(const std::string& path, const Image& image, ExrPixels pixels) {
  const Imf::PixelType type = pixels == ExrPixels::Half ? Imf::HALF : Imf::FLOAT;
  // Encoded in memory, then written by writeFileAtomic: OpenEXR's own file output ignores
  // errors in its destructor (the last block and the offset table), so a full disk could
  // leave a truncated file under the final name.
  MemoryOStream encoded;
  try {
    Imf::Header header(image.width, image.height);
    header.compression() = Imf::ZIP_COMPRESSION;
    const char* names[4] = {"R", "G", "B", "A"};
    for (const char* n : names) header.channels().insert(n, Imf::Channel(type));
    Imf::FrameBuffer fb;
    // Half output converts from a float frame buffer only through a half copy.
    std::vector<half> halves;
    if (type == Imf::HALF) {
      halves.resize(image.rgba.size());
      for (size_t i = 0; i < halves.size(); ++i) halves[i] = half(image.rgba[i]);
      for (int c = 0; c < 4; ++c)
        fb.insert(names[c], Imf::Slice(Imf::HALF, reinterpret_cast<char*>(halves.data() + c),
                                       sizeof(half) * 4, sizeof(half) * 4 * image.width));
    } else {
      for (int c = 0; c < 4; ++c)
        fb.insert(
            names[c],
            Imf::Slice(Imf::FLOAT,
                       const_cast<char*>(reinterpret_cast<const char*>(image.rgba.data() + c)),
                       sizeof(float) * 4, sizeof(float) * 4 * image.width));
    }
    // Extra channels: each in its own array, converted where it is written as half.
    std::vector<std::vector<half>> channelHalves(image.channels.size());
    for (size_t k = 0; k < image.channels.size(); ++k) {
      const ImageChannel& c = image.channels[k];
      if (c.values.size() != image.rgba.size() / 4)
        throw std::runtime_error("channel " + c.name + " has the wrong size");
      const Imf::PixelType ct = c.fullFloat ? Imf::FLOAT : type;
      header.channels().insert(c.name, Imf::Channel(ct));
      if (ct == Imf::HALF) {
        channelHalves[k].assign(c.values.begin(), c.values.end());
        fb.insert(c.name, Imf::Slice(Imf::HALF, reinterpret_cast<char*>(channelHalves[k].data()),
                                     sizeof(half), sizeof(half) * image.width));
      } else {
        fb.insert(c.name,
                  Imf::Slice(Imf::FLOAT,
                             const_cast<char*>(reinterpret_cast<const char*>(c.values.data())),
                             sizeof(float), sizeof(float) * image.width));
      }
    }
    Imf::OutputFile file(encoded, header);
    file.setFrameBuffer(fb);
    file.writePixels(image.height);
  } catch (const std::exception& e) {
    throw RuntimeError(path + ": cannot write OpenEXR: " + e.what());
  }
  writeFileAtomic(path, encoded.bytes());
}

void writePng(const std::string& path, const Image& image, float exposure) {
  const float scale = std::exp2(exposure);
  std::vector<unsigned char> bytes(static_cast<size_t>(image.width) * image.height * 3);
  for (size_t i = 0, n = static_cast<size_t>(image.width) * image.height; i < n; ++i)
    for (int c = 0; c < 3; ++c) {
      const float v = image.rgba[i * 4 + c] * scale;
      bytes[i * 3 + c] =
          static_cast<unsigned char>(std::lround(srgbEncode(std::isfinite(v) ? v : 0.0f) * 255.0f));
    }
  std::string encoded;
  auto sink = [](void* ctx, void* data, int size) {
    static_cast<std::string*>(ctx)->append(static_cast<const char*>(data), size);
  };
  if (!stbi_write_png_to_func(sink, &encoded, image.width, image.height, 3, bytes.data(),
                              image.width * 3))
    throw RuntimeError(path + ": PNG encoding failed");
  writeFileAtomic(path, encoded);
}

namespace {

// Opens an OpenEXR file and calls read(file, data window, width, height); every failure is an
// InputError naming the file.
template <class Read>
auto readExrWith(const std::string& path, Read&& read) {
  MemoryIStream stream(path, readInputFile(path, kMaxImageFileBytes));
  try {
    Imf::InputFile file(stream);
    const Imath::Box2i dw = file.header().dataWindow();
    const int w = dw.max.x - dw.min.x + 1, h = dw.max.y - dw.min.y + 1;
    if (w <= 0 || h <= 0 || static_cast<long long>(w) * h > (1ll << 28))
      throw InputError(path + ": unreasonable OpenEXR data window");
    if (!file.isComplete()) throw InputError(path + ": OpenEXR file is incomplete");
    return read(file, dw, w, h);
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    std::string msg = e.what();
    std::replace(msg.begin(), msg.end(), '\n', ' ');
    throw InputError(path + ": not a readable OpenEXR file (" + msg + ")");
  }
}

// Where a frame buffer's slice starts for pixel (0, 0) of a data window at `dw`, w wide, whose
// first pixel is at `first` and pixels `stride` bytes apart.
char* sliceBase(float* first, const Imath::Box2i& dw, int w, size_t stride) {
  return reinterpret_cast<char*>(first) -
         (static_cast<ptrdiff_t>(dw.min.x) + static_cast<ptrdiff_t>(dw.min.y) * w) *
             static_cast<ptrdiff_t>(stride);
}

}  // namespace

Image readExr(const std::string& path) {
  return readExrWith(path, [&](Imf::InputFile& file, const Imath::Box2i& dw, int w, int h) {
    Image img(w, h);
    Imf::FrameBuffer fb;
    const char* names[4] = {"R", "G", "B", "A"};
    for (int c = 0; c < 4; ++c)
      fb.insert(names[c], Imf::Slice(Imf::FLOAT, sliceBase(img.rgba.data() + c, dw, w, 16), 16,
                                     size_t(16) * w, 1, 1, c == 3 ? 1.0 : 0.0));
    file.setFrameBuffer(fb);
    file.readPixels(dw.min.y, dw.max.y);
    return img;
  });
}

std::vector<float> readExrChannel(const std::string& path, const std::string& name) {
  return readExrWith(path, [&](Imf::InputFile& file, const Imath::Box2i& dw, int w, int h) {
    if (!file.header().channels().findChannel(name))
      throw InputError(path + ": no channel " + name);
    std::vector<float> values(size_t(w) * h);
    Imf::FrameBuffer fb;
    fb.insert(name, Imf::Slice(Imf::FLOAT, sliceBase(values.data(), dw, w, 4), 4, size_t(4) * w));
    file.setFrameBuffer(fb);
    file.readPixels(dw.min.y, dw.max.y);
    return values;
  });
}

bool isCompleteExr(const std::string& path) {
  try {
    readExr(path);
    return true;
  } catch (const InputError&) {
    return false;
  }
}

}  // namespace pr
