// Cairo documents (chart.pdf, chart.svg) drawn into memory, so that they reach their file
// through write_output (output_files.h: a temporary name, then rename) like every other
// output: a crash or a full disk never leaves half a chart under its real name.
//
// Use: CairoBytes out; cairo_pdf_surface_create_for_stream(CairoBytes::write, &out, w, h);
// draw, finish the surface, then write_output(file, out.bytes).
// Not thread-safe per instance (one surface writes into one CairoBytes).
#pragma once

#include <cairo.h>

#include <string>

namespace atelier {

struct CairoBytes {
  std::string bytes;
  // A cairo_write_func_t; `self` is the CairoBytes.
  static cairo_status_t write(void* self, const unsigned char* data, unsigned int length) {
    static_cast<CairoBytes*>(self)->bytes.append(reinterpret_cast<const char*>(data), length);
    return CAIRO_STATUS_SUCCESS;
  }
};

}  // namespace atelier
