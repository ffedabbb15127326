// A 5 x 7 bitmap font for the labels Lacuna draws into its pictures (renders, plots): digits,
// capitals, 'm' and a little punctuation; other lower-case letters are drawn as capitals (so that
// "mm" stays millimetres), characters without a glyph as a blank.
#pragma once

#include <functional>
#include <string>

namespace lacuna {

constexpr int kGlyphWidth = 5, kGlyphHeight = 7;

// Calls cell(column, row) for every inked cell of the text, rows from the top; each character
// advances kGlyphWidth + 1 columns.
void draw_text(const std::string& text, const std::function<void(int column, int row)>& cell);

// The text's width in cells.
inline int text_cells(const std::string& text) { return text.empty() ? 0 : int(text.size()) * (kGlyphWidth + 1) - 1; }

}  // namespace lacuna
