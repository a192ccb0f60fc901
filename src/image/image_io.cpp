// Images through OpenImageIO 2.4, which has only a C++ API: the rest of lens2pov is C and calls
// the extern "C" functions of image_io.h. This file alone is built into lens2pov-image-io.so,
// which image_io_loader.c loads on first use (OpenImageIO's libraries are slow to load);
// the .so exports those functions as image_io_impl_* (image_io_impl.h). No exception may cross
// into C, so every entry point catches everything and turns it into an l2p_error.
//
// Colour encoding is done here with the exact sRGB transfer function of IEC 61966-2-1 (the
// piecewise curve with the linear toe), not with ImageBufAlgo::colorconvert: that one depends on
// which OpenColorIO configuration is installed, and the tests pin exact 8-bit codes.

#include "base/error.h"
#include "base/cleanup.h"
#include "base/outfile.h"
#include "image/image_io_impl.h"

#include <OpenImageIO/imageio.h>
#include <OpenImageIO/strutil.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <fcntl.h>
#include <new>
#include <string>
#include <sys/stat.h>
#include <unistd.h>
#include <vector>

namespace {

using OIIO::ImageInput;
using OIIO::ImageOutput;
using OIIO::ImageSpec;
using OIIO::TypeDesc;

// Newlines become spaces: OIIO's messages may span lines, ours are one line, and attribute
// values become "name=value" lines of ImageDescription.
std::string one_line(std::string s)
{
    for (char &c : s)
        if (c == '\n' || c == '\r')
            c = ' ';
    return s;
}

int fail(l2p_error *err, int status, const char *path, const std::string &message)
{
    std::string text = one_line(message);
    while (!text.empty() && text.back() == ' ')
        text.pop_back();
    if (text.empty())
        text = "unknown OpenImageIO error";
    return l2p_fail(err, status, path, 0, "%s", text.c_str());
}

// ---- sRGB transfer (IEC 61966-2-1) ----

float srgb_encode(float linear)
{
    if (!(linear > 0.0f))            // also NaN
        return 0.0f;
    if (linear >= 1.0f)
        return 1.0f;
    if (linear <= 0.0031308f)
        return 12.92f * linear;
    return 1.055f * std::pow(linear, 1.0f / 2.4f) - 0.055f;
}

float srgb_decode(float encoded)
{
    if (encoded <= 0.04045f)
        return encoded / 12.92f;
    return std::pow((encoded + 0.055f) / 1.055f, 2.4f);
}

// ---- reading ----

// How a file's colour values relate to linear light.
struct encoding {
    enum kind { LINEAR, SRGB, GAMMA } kind;
    float gamma;
};

// Float files are linear; integer files are sRGB unless they say otherwise (PNG's gAMA chunk
// shows up as oiio:Gamma / "GammaCorrected...", POV-Ray's File_Gamma=1.0 PNG as linear).
encoding encoding_of(const ImageSpec &spec)
{
    if (spec.format.is_floating_point())
        return {encoding::LINEAR, 1.0f};
    const std::string cs = spec.get_string_attribute("oiio:ColorSpace");
    const float gamma = spec.get_float_attribute("oiio:Gamma", 0.0f);
    if (OIIO::Strutil::iequals(cs, "linear") || gamma == 1.0f)
        return {encoding::LINEAR, 1.0f};
    if (gamma > 0.0f && !OIIO::Strutil::iequals(cs, "sRGB"))
        return {encoding::GAMMA, gamma};
    return {encoding::SRGB, 1.0f};
}

float to_linear(float v, const encoding &e)
{
    switch (e.kind) {
    case encoding::SRGB:
        return srgb_decode(v);
    case encoding::GAMMA:
        return v > 0.0f ? std::pow(v, e.gamma) : 0.0f;
    default:
        return v;
    }
}

// Which file channels give R, G, B and alpha (-1: none). One or two colour channels are grey.
struct channel_map {
    int rgb[3];
    int alpha;
};

channel_map map_channels(const ImageSpec &spec)
{
    channel_map m;
    m.alpha = spec.alpha_channel;
    if (m.alpha < 0 && spec.nchannels == 2)
        m.alpha = 1;                  // grey + alpha (PNG "YA")
    std::vector<int> colour;
    for (int c = 0; c < spec.nchannels; c++)
        if (c != m.alpha)
            colour.push_back(c);
    for (int i = 0; i < 3; i++)
        m.rgb[i] = colour.size() >= 3 ? colour[i] : colour.empty() ? -1 : colour[0];
    return m;
}

// Source pixels (nc file channels each) to linear RGBA with associated alpha, as EXR stores
// it. dst may be src when nc is at most 4: the pixels go last first, each read whole before
// it is written, and pixel i's RGBA covers only the channels of pixels i and above. So a
// picture needs one buffer, filled by the reader.
void convert_to_rgba(const ImageSpec &spec, const float *src, float *dst)
{
    const channel_map m = map_channels(spec);
    const encoding e = encoding_of(spec);
    const size_t n = (size_t)spec.width * (size_t)spec.height, nc = (size_t)spec.nchannels;
    for (size_t i = n; i-- > 0;) {
        const float *s = &src[i * nc];
        const float a = m.alpha >= 0 ? s[m.alpha] : 1.0f;
        float rgba[4];
        for (int c = 0; c < 3; c++) {
            const float v = m.rgb[c] >= 0 ? to_linear(s[m.rgb[c]], e) : 0.0f;
            // Integer files were read unassociated so that decoding sees the true colour.
            rgba[c] = e.kind == encoding::LINEAR ? v : v * a;
        }
        rgba[3] = a;
        std::memcpy(&dst[4 * i], rgba, sizeof rgba);
    }
}

int read_rgba(const char *path, int *width, int *height, float **pixels, l2p_error *err)
{
    struct stat st;
    if (stat(path, &st) != 0)
        return fail(err, errno == ENOENT || errno == ENOTDIR ? L2P_BAD_INPUT : L2P_FAILED, path,
                    std::string("cannot read: ") + std::strerror(errno));
    ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    auto in = ImageInput::open(path, &config);
    // A file that is there but cannot be decoded is bad input (exit 2), as a bad lens file is.
    if (!in)
        return fail(err, L2P_BAD_INPUT, path, OIIO::geterror());
    const ImageSpec spec = in->spec();
    if (spec.deep || spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0)
        return fail(err, L2P_BAD_INPUT, path, "not a flat image with pixels");
    const size_t n = (size_t)spec.width * spec.height;
    const bool in_place = spec.nchannels <= 4;
    std::vector<float> other(in_place ? 0 : n * spec.nchannels);
    float *out = (float *)std::malloc(sizeof(float) * 4 * n);
    if (!out)
        return fail(err, L2P_FAILED, path, "out of memory");
    float *src = in_place ? out : other.data();
    if (!in->read_image(0, 0, 0, spec.nchannels, TypeDesc::FLOAT, src)) {
        std::free(out);
        return fail(err, L2P_BAD_INPUT, path, in->geterror());
    }
    convert_to_rgba(spec, src, out);
    *width = spec.width;
    *height = spec.height;
    *pixels = out;
    return L2P_OK;
}

// ---- writing ----

enum class file_kind { PNG, TIFF, EXR, UNKNOWN };

// The extension of the file name (not of a folder), with its dot; empty when there is none.
std::string extension_of(const std::string &path)
{
    const size_t slash = path.find_last_of('/');
    const size_t dot = path.find_last_of('.');
    if (dot == std::string::npos || (slash != std::string::npos && dot < slash) ||
        dot == (slash == std::string::npos ? 0 : slash + 1))
        return "";
    return path.substr(dot);
}

file_kind kind_of(const std::string &ext)
{
    std::string e = ext;
    std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return std::tolower(c); });
    if (e == ".png")
        return file_kind::PNG;
    if (e == ".tif" || e == ".tiff")
        return file_kind::TIFF;
    if (e == ".exr")
        return file_kind::EXR;
    return file_kind::UNKNOWN;
}

// "<dir>/.<base>.tmp<random><ext>", created empty and exclusively by outfile_create_temp, for
// OpenImageIO to write: beside the output (so rename is atomic), hidden, and keeping the
// extension so that OpenImageIO picks the same writer.
int make_temp(const std::string &path, const std::string &ext, std::string &temp, l2p_error *err)
{
    const size_t slash = path.find_last_of('/');
    const std::string dir = slash == std::string::npos ? "" : path.substr(0, slash + 1);
    const std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
    const std::string base = name.substr(0, name.size() - ext.size());
    char *made = nullptr;
    const int fd = outfile_create_temp((dir + "." + base + ".tmp").c_str(), ext.c_str(), &made);
    if (fd < 0)
        return fail(err, errno == ENOENT || errno == ENOTDIR ? L2P_BAD_INPUT : L2P_FAILED,
                    path.c_str(), std::string("cannot write: ") + std::strerror(errno));
    close(fd);
    temp = made;
    std::free(made);
    return L2P_OK;
}

// A missing folder is the user's mistake (status 2), as in outfile_open.
int check_folder(const std::string &path, l2p_error *err)
{
    const size_t slash = path.find_last_of('/');
    const std::string dir = slash == std::string::npos ? "." : path.substr(0, slash + 1);
    struct stat st;
    if (stat(dir.c_str(), &st) != 0)
        return fail(err, errno == ENOENT || errno == ENOTDIR ? L2P_BAD_INPUT : L2P_FAILED,
                    path.c_str(), std::string("cannot write: ") + std::strerror(errno));
    if (!S_ISDIR(st.st_mode))
        return fail(err, L2P_BAD_INPUT, path.c_str(), "cannot write: Not a directory");
    return L2P_OK;
}

// OIIO's standard names for the attributes lens2pov passes, with their types: OIIO's own Exif
// name for the f-number is "FNumber" (written into TIFF's Exif block); EXR readers also look
// for "Exif:FNumber".
void add_standard_attribute(ImageSpec &spec, const char *name, const char *value)
{
    char *end = nullptr;
    const float number = std::strtof(value, &end);
    const bool is_number = end != value && *end == '\0' && std::isfinite(number);
    if (std::strcmp(name, "FNumber") == 0 && is_number) {
        spec.attribute("FNumber", number);
        spec.attribute("Exif:FNumber", number);
    } else if (std::strcmp(name, "FocalLength") == 0 && is_number) {
        spec.attribute("Exif:FocalLength", number);
    } else {
        spec.attribute(name, one_line(value));
    }
}

// Every attribute also goes into ImageDescription as "name=value" lines, because TIFF keeps
// no attributes of its own invention and PNG no Exif: the description survives in all three.
void add_attributes(ImageSpec &spec, const image_attribute *attributes, int count)
{
    std::string description;
    bool has_description = false;
    for (int i = 0; i < count; i++) {
        const char *name = attributes[i].name;
        const char *value = attributes[i].value ? attributes[i].value : "";
        if (!name || !*name)
            continue;
        add_standard_attribute(spec, name, value);
        has_description |= OIIO::Strutil::iequals(name, "ImageDescription");
        if (!OIIO::Strutil::iequals(name, "Software"))
            description += std::string(name) + "=" + one_line(value) + "\n";
    }
    if (!has_description && !description.empty())
        spec.attribute("ImageDescription", description);
}

// Whether half floats keep every value to their 11 bits: none nonzero below the smallest
// normal half, 2^-14 (physical weights through a tiny stop give 1e-8), nor above the largest.
bool fits_half(const float *pixels, size_t count)
{
    for (size_t i = 0; i < count; i++) {
        const float a = std::fabs(pixels[i]);
        if (a != 0.0f && (a < 0x1.0p-14f || a > 65504.0f))
            return false;
    }
    return true;
}

ImageSpec make_spec(file_kind kind, int width, int height, bool half)
{
    const TypeDesc type = kind == file_kind::PNG    ? TypeDesc::UINT8
                          : kind == file_kind::TIFF ? TypeDesc::UINT16
                          : half                    ? TypeDesc::HALF
                                                    : TypeDesc::FLOAT;
    ImageSpec spec(width, height, 3, type);
    spec.attribute("oiio:ColorSpace", kind == file_kind::EXR ? "Linear" : "sRGB");
    if (kind != file_kind::PNG)
        spec.attribute("compression", "zip");
    return spec;
}

// Encoded integer samples, rounded to nearest: code = round(srgb(clip(v)) * max).
template <typename T>
std::vector<T> encode_srgb(const float *pixels, size_t count, float max_code)
{
    std::vector<T> out(count);
    for (size_t i = 0; i < count; i++)
        out[i] = (T)std::lround(srgb_encode(pixels[i]) * max_code);
    return out;
}

bool write_pixels(ImageOutput &out, file_kind kind, const float *pixels, size_t count)
{
    if (kind == file_kind::PNG)
        return out.write_image(TypeDesc::UINT8, encode_srgb<uint8_t>(pixels, count, 255.0f).data());
    if (kind == file_kind::TIFF)
        return out.write_image(TypeDesc::UINT16,
                               encode_srgb<uint16_t>(pixels, count, 65535.0f).data());
    return out.write_image(TypeDesc::FLOAT, pixels);   // OIIO rounds to half where asked
}

// The file under temp on the disk (fsync), and a PNG ending in its IEND chunk: OpenImageIO's
// PNG writer reports no failed write, and a full disk or a file size limit left a truncated
// picture that replaced a good one with exit 0. (Reading it back through libpng would say so
// too, but prints libpng's own error on stderr.)
int check_written(const std::string &temp, const char *path, file_kind kind, l2p_error *err)
{
    static const unsigned char iend[12] = {0, 0, 0, 0, 'I', 'E', 'N', 'D', 0xae, 0x42, 0x60, 0x82};
    const int fd = open(temp.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0 || fsync(fd) != 0) {
        const int e = errno;
        if (fd >= 0)
            close(fd);
        return fail(err, L2P_FAILED, path, std::string("cannot write: ") + std::strerror(e));
    }
    unsigned char tail[12];
    struct stat st;
    const bool whole = kind != file_kind::PNG ||
                       (fstat(fd, &st) == 0 && st.st_size >= 12 &&
                        pread(fd, tail, sizeof tail, st.st_size - 12) == (ssize_t)sizeof tail &&
                        std::memcmp(tail, iend, sizeof tail) == 0);
    close(fd);
    return whole ? L2P_OK
                 : fail(err, L2P_FAILED, path, "cannot write: the picture written is incomplete "
                                               "(is the disk full?)");
}

// Writes the complete file under temp; the caller renames it.
int write_temp(const std::string &temp, const char *path, file_kind kind, const ImageSpec &spec,
               const float *pixels, l2p_error *err)
{
    auto out = ImageOutput::create(temp);
    if (!out)
        return fail(err, L2P_FAILED, path, OIIO::geterror());
    const size_t count = (size_t)spec.width * spec.height * 3;
    if (!out->open(temp, spec) || !write_pixels(*out, kind, pixels, count) || !out->close()) {
        const std::string message = out->geterror();
        return fail(err, L2P_FAILED, path, "cannot write: " + message);
    }
    return check_written(temp, path, kind, err);
}

int write_rgb(const char *path, int width, int height, const float *pixels,
              const image_attribute *attributes, int attribute_count, l2p_error *err)
{
    const std::string ext = extension_of(path);
    const file_kind kind = kind_of(ext);
    if (kind == file_kind::UNKNOWN)
        return l2p_fail(err, L2P_BAD_INPUT, path, 0,
                        "unknown image type '%s' (use .png, .exr or .tif)", ext.c_str());
    if (width <= 0 || height <= 0 || !pixels)
        return l2p_fail(err, L2P_FAILED, path, 0, "no pixels to write (%dx%d)", width, height);
    char *to = outfile_target(path);   // written through a symbolic link, which stays
    if (!to)
        return fail(err, errno == ENOMEM ? L2P_FAILED : L2P_BAD_INPUT, path,
                    std::string("cannot write: ") + std::strerror(errno));
    const std::string target = to;
    std::free(to);
    int st = check_folder(target, err);
    if (st)
        return st;
    ImageSpec spec = make_spec(kind, width, height,
                               fits_half(pixels, (size_t)width * (size_t)height * 3));
    add_attributes(spec, attributes, attribute_count);
    std::string temp;
    if ((st = make_temp(target, ext, temp, err)))
        return st;
    cleanup_track(temp.c_str());
    try {
        st = write_temp(temp, path, kind, spec, pixels, err);
    } catch (...) {
        unlink(temp.c_str());
        cleanup_untrack(temp.c_str());
        throw;
    }
    if (!st && std::rename(temp.c_str(), target.c_str()) != 0)
        st = fail(err, L2P_FAILED, path, std::string("cannot rename into place: ") +
                                             std::strerror(errno));
    if (st)
        unlink(temp.c_str());
    cleanup_untrack(temp.c_str());
    return st;
}

// ---- attributes read back ----

// The value of "name=" among the "name=value" lines of an ImageDescription.
bool from_description(const std::string &description, const std::string &name, std::string &value)
{
    const std::string key = name + "=";
    size_t start = 0;
    while (start < description.size()) {
        size_t end = description.find('\n', start);
        if (end == std::string::npos)
            end = description.size();
        if (description.compare(start, key.size(), key) == 0) {
            value = description.substr(start + key.size(), end - start - key.size());
            return true;
        }
        start = end + 1;
    }
    return false;
}

bool find_attribute(const char *path, const char *name, std::string &value)
{
    auto in = ImageInput::open(path);
    if (!in) {
        OIIO::geterror();   // clear the thread's pending error
        return false;
    }
    const ImageSpec &spec = in->spec();
    if (const OIIO::ParamValue *p = spec.find_attribute(name)) {
        value = p->get_string();
        return true;
    }
    return from_description(spec.get_string_attribute("ImageDescription"), name, value);
}

int caught(l2p_error *err, const char *path)
{
    try {
        throw;
    } catch (const std::bad_alloc &) {
        return fail(err, L2P_FAILED, path, "out of memory");
    } catch (const std::exception &e) {
        return fail(err, L2P_FAILED, path, std::string("OpenImageIO: ") + e.what());
    } catch (...) {
        return fail(err, L2P_FAILED, path, "OpenImageIO: unknown exception");
    }
}

}  // namespace

extern "C" int image_io_impl_read_rgba(const char *path, int *width, int *height,
                                       float **pixels, l2p_error *err)
{
    try {
        return read_rgba(path, width, height, pixels, err);
    } catch (...) {
        return caught(err, path);
    }
}

extern "C" int image_io_impl_write_rgb(const char *path, int width, int height,
                                       const float *pixels, const image_attribute *attributes,
                                       int attribute_count, l2p_error *err)
{
    try {
        return write_rgb(path, width, height, pixels, attributes, attribute_count, err);
    } catch (...) {
        return caught(err, path);
    }
}

extern "C" int image_io_impl_get_attribute(const char *path, const char *name, char *buf,
                                           size_t len)
{
    try {
        std::string value;
        if (!find_attribute(path, name, value))
            return L2P_FAILED;
        if (buf && len > 0)
            std::snprintf(buf, len, "%s", value.c_str());
        return L2P_OK;
    } catch (...) {
        return L2P_FAILED;
    }
}
