/* XML documents as a plain C tree, parsed by pugixml (xml.cpp, the only C++
 * in the library): elements with their attributes, children and 1-based
 * source lines; text, comments and processing instructions are dropped.
 * Readers of XML scene formats (mitsuba_*.c) walk this tree. */
#ifndef CDL_XML_H
#define CDL_XML_H

#include "core/error.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct cdl_xml_attr {
    char *name, *value;
} cdl_xml_attr;

typedef struct cdl_xml_node {
    char *name;
    int line;
    int used; /* for the reader: set when it consumed the element */
    cdl_xml_attr *attrs;
    int nattrs;
    struct cdl_xml_node *kids;
    int nkids;
} cdl_xml_node;

typedef struct cdl_xml_doc {
    cdl_xml_node root; /* the document element */
} cdl_xml_doc;

/* Parses path (at most 256 MB); a malformed document is an error naming
 * the file, the line and pugixml's description. */
int cdl_xml_load(const char *path, cdl_xml_doc *doc, cdl_error *err);
void cdl_xml_free(cdl_xml_doc *doc);

/* The attribute's value or NULL. */
const char *cdl_xml_attr_get(const cdl_xml_node *n, const char *name);

#ifdef __cplusplus
}
#endif

#endif
