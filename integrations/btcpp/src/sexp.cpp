#include "sexp.hpp"

#include <cstdlib>
#include <string_view>

#include "btc/kb.hpp"

namespace btc::detail
{
namespace
{

bool isSpace(char c)
{
  return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v';
}

// Bytes of multi-byte UTF-8 characters count as letters, as Rust's
// `char::is_alphanumeric` counts most of them.
bool isNameChar(unsigned char c)
{
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
         c == '-' || c == '_' || c == '.' || c == '@' || c >= 0x80;
}

bool isDigit(char c)
{
  return c >= '0' && c <= '9';
}

bool looksNumeric(std::string_view w)
{
  if(w.empty())
  {
    return false;
  }
  if(isDigit(w[0]))
  {
    return true;
  }
  if(w.size() >= 2 && (w[0] == '-' || w[0] == '+' || w[0] == '.') && isDigit(w[1]))
  {
    return true;
  }
  return w.size() >= 3 && (w[0] == '-' || w[0] == '+') && w[1] == '.' && isDigit(w[2]);
}

bool isOperator(std::string_view w)
{
  return w == "=" || w == "<" || w == ">" || w == "<=" || w == ">=" || w == "+" || w == "*" ||
         w == "/";
}

std::string lower(std::string_view s)
{
  std::string out(s);
  for(auto& c : out)
  {
    if(c >= 'A' && c <= 'Z')
    {
      c = static_cast<char>(c - 'A' + 'a');
    }
  }
  return out;
}

class Reader
{
public:
  Reader(const std::string& text, const std::string& origin) : text_(text), origin_(origin) {}

  std::vector<Sexp> all()
  {
    std::vector<Sexp> out;
    // An explicit stack: deep nesting never overflows the C++ stack.
    std::vector<Sexp> open;
    while(true)
    {
      skipBlanks();
      if(pos_ >= text_.size())
      {
        break;
      }
      const char c = text_[pos_];
      if(c == '(')
      {
        if(open.size() >= kMaxDepth)
        {
          fail(pos_, "parentheses nested deeper than " + std::to_string(kMaxDepth));
        }
        Sexp l;
        l.kind = Sexp::Kind::List;
        l.offset = pos_++;
        open.push_back(std::move(l));
        continue;
      }
      if(c == ')')
      {
        if(open.empty())
        {
          fail(pos_, "this `)` closes nothing");
        }
        ++pos_;
        Sexp done = std::move(open.back());
        open.pop_back();
        (open.empty() ? out : open.back().items).push_back(std::move(done));
        continue;
      }
      Sexp w = word();
      (open.empty() ? out : open.back().items).push_back(std::move(w));
    }
    if(!open.empty())
    {
      fail(open.back().offset, "this `(` is never closed");
    }
    return out;
  }

private:
  static constexpr std::size_t kMaxDepth = 200;

  void skipBlanks()
  {
    while(pos_ < text_.size())
    {
      if(isSpace(text_[pos_]))
      {
        ++pos_;
      }
      else if(text_[pos_] == ';')
      {
        while(pos_ < text_.size() && text_[pos_] != '\n')
        {
          ++pos_;
        }
      }
      else
      {
        break;
      }
    }
  }

  Sexp word()
  {
    const std::size_t start = pos_;
    while(pos_ < text_.size() && !isSpace(text_[pos_]) && text_[pos_] != '(' &&
          text_[pos_] != ')' && text_[pos_] != ';')
    {
      ++pos_;
    }
    const std::string_view w(text_.data() + start, pos_ - start);
    Sexp s;
    s.offset = start;
    if(w == "-")
    {
      s.kind = Sexp::Kind::Dash;
      s.text = "-";
      return s;
    }
    if(isOperator(w))
    {
      s.kind = Sexp::Kind::Name;
      s.text = std::string(w);
      return s;
    }
    if(looksNumeric(w))
    {
      const std::string copy(w);
      char* end = nullptr;
      const double x = std::strtod(copy.c_str(), &end);
      if(end == copy.c_str() + copy.size())
      {
        s.kind = Sexp::Kind::Number;
        s.number = x;
        s.text = copy;
        return s;
      }
    }
    std::string_view rest = w;
    s.kind = Sexp::Kind::Name;
    if(w[0] == '?')
    {
      s.kind = Sexp::Kind::Var;
      rest = w.substr(1);
    }
    else if(w[0] == ':')
    {
      s.kind = Sexp::Kind::Keyword;
      rest = w.substr(1);
    }
    bool ok = !rest.empty();
    for(const char c : rest)
    {
      ok = ok && isNameChar(static_cast<unsigned char>(c));
    }
    if(!ok)
    {
      fail(start, "`" + std::string(w) +
                      "` is not a PDDL name (names are letters, digits, `-` and `_`)");
    }
    s.text = lower(rest);
    return s;
  }

  [[noreturn]] void fail(std::size_t at, const std::string& msg) const
  {
    std::size_t line = 1;
    std::size_t col = 1;
    for(std::size_t i = 0; i < at && i < text_.size(); ++i)
    {
      if(text_[i] == '\n')
      {
        ++line;
        col = 1;
      }
      else
      {
        ++col;
      }
    }
    throw KbError(origin_ + ":" + std::to_string(line) + ":" + std::to_string(col) + ": " +
                  msg);
  }

  const std::string& text_;
  const std::string& origin_;
  std::size_t pos_ = 0;
};

}  // namespace

const std::string* Sexp::head() const
{
  if(kind != Kind::List || items.empty() || items[0].kind != Kind::Name)
  {
    return nullptr;
  }
  return &items[0].text;
}

std::string Sexp::show() const
{
  switch(kind)
  {
    case Kind::Var:
      return "?" + text;
    case Kind::Keyword:
      return ":" + text;
    case Kind::List: {
      std::string s = "(";
      for(std::size_t i = 0; i < items.size(); ++i)
      {
        if(i > 0)
        {
          s += ' ';
        }
        s += items[i].show();
      }
      return s + ")";
    }
    default:
      return text;
  }
}

std::vector<Sexp> readSexps(const std::string& text, const std::string& origin)
{
  return Reader(text, origin).all();
}

Sexp readOne(const std::string& text, const std::string& what)
{
  auto forest = readSexps(text, what);
  if(forest.size() != 1)
  {
    throw KbError(what + ": expected one parenthesised PDDL expression, found " +
                  std::to_string(forest.size()));
  }
  return std::move(forest[0]);
}

}  // namespace btc::detail
