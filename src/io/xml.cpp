// pugixml parses; this file copies the element tree into C structures so the
// readers stay C. Nothing here throws past the C boundary.
#include <pugixml.hpp>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <new>

extern "C" {
#include "core/file.h"
#include "io/xml.h"
}

namespace {

// Deeper nesting than any scene format uses; bounds the copy's recursion.
const int max_depth = 64;

struct copier {
    size_t *line_starts = nullptr; // offset of each line's first byte (malloc'd: no
    size_t nlines = 0;             // exported std:: template instances in the library)
    const char *path;
    cdl_error *err;
    int rc = 0;

    int line_of(ptrdiff_t off) const
    {
        if (off < 0)
            return 0;
        size_t lo = 0, hi = nlines;
        while (hi - lo > 1) {
            size_t mid = (lo + hi) / 2;
            if (line_starts[mid] <= (size_t)off)
                lo = mid;
            else
                hi = mid;
        }
        return (int)lo + 1;
    }

    char *dup(const char *s)
    {
        char *d = strdup(s);
        if (!d && !rc)
            rc = cdl_error_set(err, CDL_ERR_SYSTEM, path, 0, "out of memory");
        return d;
    }

    void copy(const pugi::xml_node &src, cdl_xml_node *dst, int depth)
    {
        dst->name = dup(src.name());
        dst->line = line_of(src.offset_debug());
        if (rc)
            return;
        if (depth > max_depth) {
            rc = cdl_error_set(err, CDL_ERR_INPUT, path, dst->line, "elements nested deeper than %d", max_depth);
            return;
        }
        int na = 0, nk = 0;
        for (pugi::xml_attribute a = src.first_attribute(); a; a = a.next_attribute())
            na++;
        for (pugi::xml_node k = src.first_child(); k; k = k.next_sibling())
            if (k.type() == pugi::node_element)
                nk++;
        if (na) {
            dst->attrs = (cdl_xml_attr *)calloc((size_t)na, sizeof *dst->attrs);
            if (!dst->attrs) {
                rc = cdl_error_set(err, CDL_ERR_SYSTEM, path, 0, "out of memory");
                return;
            }
            for (pugi::xml_attribute a = src.first_attribute(); a && !rc; a = a.next_attribute()) {
                cdl_xml_attr *d = &dst->attrs[dst->nattrs++];
                d->name = dup(a.name());
                d->value = dup(a.value());
            }
        }
        if (nk && !rc) {
            dst->kids = (cdl_xml_node *)calloc((size_t)nk, sizeof *dst->kids);
            if (!dst->kids) {
                rc = cdl_error_set(err, CDL_ERR_SYSTEM, path, 0, "out of memory");
                return;
            }
            for (pugi::xml_node k = src.first_child(); k && !rc; k = k.next_sibling())
                if (k.type() == pugi::node_element)
                    copy(k, &dst->kids[dst->nkids++], depth + 1);
        }
    }
};

void free_node(cdl_xml_node *n)
{
    for (int i = 0; i < n->nattrs; i++) {
        free(n->attrs[i].name);
        free(n->attrs[i].value);
    }
    free(n->attrs);
    for (int i = 0; i < n->nkids; i++)
        free_node(&n->kids[i]);
    free(n->kids);
    free(n->name);
}

} // namespace

extern "C" int cdl_xml_load(const char *path, cdl_xml_doc *doc, cdl_error *err)
{
    memset(doc, 0, sizeof *doc);
    char *data;
    size_t size;
    int rc = cdl_read_file(path, (uint64_t)256 << 20, &data, &size, err);
    if (rc)
        return rc;
    copier c;
    try {
        c.path = path;
        c.err = err;
        size_t nl = 1;
        for (size_t i = 0; i < size; i++)
            nl += data[i] == '\n';
        if (!(c.line_starts = (size_t *)malloc(nl * sizeof(size_t)))) {
            free(data);
            return cdl_error_set(err, CDL_ERR_SYSTEM, path, 0, "out of memory");
        }
        c.line_starts[c.nlines++] = 0;
        for (size_t i = 0; i < size; i++)
            if (data[i] == '\n')
                c.line_starts[c.nlines++] = i + 1;
        pugi::xml_document xd;
        // parse_default keeps offsets valid for offset_debug(); no DOCTYPE entities are expanded.
        pugi::xml_parse_result res = xd.load_buffer(data, size, pugi::parse_default, pugi::encoding_auto);
        if (!res) {
            rc = cdl_error_set(err, CDL_ERR_INPUT, path, c.line_of(res.offset), "malformed XML: %s",
                               res.description());
        } else if (!xd.document_element()) {
            rc = cdl_error_set(err, CDL_ERR_INPUT, path, 0, "no XML element in the file");
        } else {
            c.copy(xd.document_element(), &doc->root, 0);
            rc = c.rc;
        }
    } catch (const std::bad_alloc &) {
        rc = cdl_error_set(err, CDL_ERR_SYSTEM, path, 0, "out of memory");
    }
    free(c.line_starts);
    free(data);
    if (rc)
        cdl_xml_free(doc);
    return rc;
}

extern "C" void cdl_xml_free(cdl_xml_doc *doc)
{
    free_node(&doc->root);
    memset(doc, 0, sizeof *doc);
}

extern "C" const char *cdl_xml_attr_get(const cdl_xml_node *n, const char *name)
{
    for (int i = 0; i < n->nattrs; i++)
        if (!strcmp(n->attrs[i].name, name))
            return n->attrs[i].value;
    return nullptr;
}
