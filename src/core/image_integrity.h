#pragma once
// Is an image file whole? A JPEG cut short still decodes (libjpeg fills the missing rows with grey and warns), and so
// does a PNG whose last IDAT is cut or whose bytes were flipped in a chunk the decoder skips; a measurement on such an
// image reads the fill as a flat region. ReadImage (core/image.h) checks every file it reads with this.
#include <filesystem>
#include <string_view>

namespace blurcue {

// Throws Error(kInput) naming `path` when `bytes` (the whole file) are a damaged or truncated JPEG or PNG:
//   JPEG - every marker segment whole and the stream ended by the end-of-image marker (FFD9) after its last scan
//          (bytes after it, such as a phone's appended motion video, are not looked at);
//   PNG  - every chunk whole, its CRC-32 right, and the IEND chunk reached.
// Other formats (TIFF, BMP, WebP, ...) are left to their decoder. Reads each byte once (~1 ms per 4 MB).
void RequireIntactImage(const std::filesystem::path& path, std::string_view bytes);

// True when a decoder's warning text says the data it decoded ended early or was corrupt (libjpeg's "Premature end
// of JPEG file", "Corrupt JPEG data: premature end of data segment"): the image it returned is partly fill.
bool DecoderSaysDamaged(std::string_view decoder_text);

}  // namespace blurcue
