#include "draw/svg.h"

#include <math.h>

static double width_px(const svg_view *v) { return 2 * v->margin_px + (v->zmax - v->zmin) * v->scale; }
static double height_px(const svg_view *v) { return 2 * v->margin_px + 2 * v->ymax * v->scale + 30.0; }

/* The style. Lines are drawn in the group scaled to millimetres, so their widths and dashes
   are given in pixels divided by the scale (vector-effect would do it, but not every renderer
   has it). */
static void style(FILE *out, double scale)
{
    const double px = 1.0 / scale;
    fprintf(out, "<style>\n"
                 "  .axis { stroke: #888; stroke-width: %.6g; stroke-dasharray: %.6g %.6g; }\n"
                 "  .element { fill: #cfe1f2; stroke: #1f3b5a; stroke-width: %.6g; }\n"
                 "  .stop { stroke: #000; stroke-width: %.6g; }\n"
                 "  .pupil { stroke: #2a8a2a; stroke-width: %.6g; }\n"
                 "  .film { stroke: #000; stroke-width: %.6g; }\n"
                 "  .ray { fill: none; stroke-width: %.6g; }\n"
                 "  .axial { stroke: #d62728; }\n"
                 "  .field { stroke: #1f77b4; }\n"
                 "  .blocked { stroke-dasharray: %.6g %.6g; opacity: 0.5; }\n",
            px, 6 * px, 4 * px, 1.2 * px, 3 * px, 2.5 * px, 2 * px, 0.8 * px, 3 * px, 3 * px);
    fputs("  .mark { stroke: #7b3294; stroke-width: 1.5; }\n"
          "  .bar { stroke: #000; stroke-width: 2; fill: none; }\n"
          "  text { font-family: sans-serif; font-size: 12px; text-anchor: middle; }\n"
          "  text.title { font-size: 14px; text-anchor: start; }\n"
          "</style>\n", out);
}

void svg_begin(FILE *out, const svg_view *v)
{
    const double w = width_px(v), h = height_px(v);
    fprintf(out, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
                 "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" height=\"%.0f\" "
                 "viewBox=\"0 0 %.0f %.0f\">\n", ceil(w), ceil(h), ceil(w), ceil(h));
    style(out, v->scale);
    fputs("<rect width=\"100%\" height=\"100%\" fill=\"#fff\"/>\n", out);
    /* x = -s z + (margin + s zmax), y = -s y + (margin + s ymax): svg_x and svg_y. */
    fprintf(out, "<g transform=\"matrix(%.17g 0 0 %.17g %.17g %.17g)\">\n", -v->scale, -v->scale,
            v->margin_px + v->scale * v->zmax, v->margin_px + v->scale * v->ymax);
}

void svg_end_group(FILE *out)
{
    fputs("</g>\n", out);
}

void svg_text(FILE *out, const char *class, double x, double y, const char *text)
{
    fprintf(out, "<text class=\"%s\" x=\"%.2f\" y=\"%.2f\">", class, x, y);
    for (const char *p = text; *p; p++) {
        const unsigned char ch = (unsigned char)*p;
        if (ch == '&')
            fputs("&amp;", out);
        else if (ch == '<')
            fputs("&lt;", out);
        else if (ch == '>')
            fputs("&gt;", out);
        else if (ch < 32 || ch > 126)
            fputc('?', out);   /* control characters are not XML 1.0, other bytes may not be UTF-8 */
        else
            fputc(ch, out);
    }
    fputs("</text>\n", out);
}

void svg_scale_bar(FILE *out, const svg_view *v)
{
    /* About a sixth of the drawing, rounded down to 1, 2 or 5 times a power of ten. */
    const double want = (v->zmax - v->zmin) / 6.0, decade = pow(10.0, floor(log10(want)));
    const double length = want >= 5 * decade ? 5 * decade : want >= 2 * decade ? 2 * decade : decade;
    const double x0 = v->margin_px, y = height_px(v) - 16.0, x1 = x0 + length * v->scale;
    fprintf(out, "<path class=\"bar\" d=\"M %.2f %.2f L %.2f %.2f M %.2f %.2f L %.2f %.2f M %.2f "
                 "%.2f L %.2f %.2f\"/>\n", x0, y, x1, y, x0, y - 5, x0, y + 5, x1, y - 5, x1, y + 5);
    char label[64];
    snprintf(label, sizeof label, "%g mm", length);
    svg_text(out, "label", 0.5 * (x0 + x1), y - 8.0, label);
}

void svg_finish(FILE *out)
{
    fputs("</svg>\n", out);
}
