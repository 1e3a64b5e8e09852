// OpenEXR's validator, as its `exrcheck` tool runs it (Debian packages the library function,
// not the tool): every file named is read through the library's read paths, its C core's
// included; prints "ok" or "bad" per file and exits 1 if any is bad. Built by the tests that
// use it (tests/common/exrcheck.rs) against libopenexr-dev.
#include <OpenEXR/ImfCheckFile.h>
#include <cstdio>

int main(int argc, char** argv)
{
    int bad = 0;
    for (int i = 1; i < argc; ++i) {
        // As exrcheck does: true means a problem was found.
        bool problem = OPENEXR_IMF_NAMESPACE::checkOpenEXRFile(argv[i], false, false, true);
        std::printf("%s: %s\n", argv[i], problem ? "bad" : "ok");
        bad |= problem;
    }
    return bad;
}
