// Checks that mesh files must pass before assimp reads them (assimp trusts what a file declares: see mesh_file.cpp).
#pragma once

#include <cstdint>
#include <string>

namespace batchcol::detail {

/// PLY (mesh_ply.cpp). A file named .ply must start with the "ply" magic; a file starting with it (under any name:
/// assimp picks its PLY reader by content) must have a valid header, and a body holding exactly the elements the
/// header declares. Throws InputError naming `what`; returns quietly for a non-PLY file not named .ply.
void check_ply(const std::string& path, std::uint64_t size, const std::string& what, bool ply_extension);

}  // namespace batchcol::detail
