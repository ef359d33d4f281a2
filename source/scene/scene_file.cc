// Boost's JSON reader includes boost/bind.hpp, which otherwise notes at every
// build that its placeholders in the global namespace are deprecated.
#define BOOST_BIND_GLOBAL_PLACEHOLDERS

#include <algorithm>
#include <boost/property_tree/json_parser.hpp>
#include <boost/property_tree/ptree.hpp>
#include <cctype>
#include <cstdio>
#include <deal.II/base/utilities.h>
#include <filesystem>
#include <fstream>
#include <membranes/scene/parameters.h>
#include <optional>
#include <sstream>
#include <vector>

namespace membranes::Parameters
{
  using dealii::Utilities::trim;

  namespace
  {
    /**
     * The length of the valid UTF-8 sequence at @p i of @p text and its
     * code point; length 0 if the bytes there are not one.
     */
    std::pair<std::size_t, char32_t>
    utf8_at(const std::string &text, const std::size_t i)
    {
      const auto        c      = static_cast<unsigned char>(text[i]);
      const std::size_t length = (c < 0x80           ? 1 :
                                  (c & 0xe0) == 0xc0 ? 2 :
                                  (c & 0xf0) == 0xe0 ? 3 :
                                  (c & 0xf8) == 0xf0 ? 4 :
                                                       0);
      if (length == 0 || i + length > text.size())
        return {0, 0};
      char32_t point = (length == 1 ? c : c & (0x7f >> length));
      for (std::size_t k = 1; k < length; ++k)
        {
          const auto d = static_cast<unsigned char>(text[i + k]);
          if ((d & 0xc0) != 0x80)
            return {0, 0};
          point = (point << 6) | (d & 0x3f);
        }
      return {length, point};
    }

    /**
     * Whether @p point is shown as a visible character: not a control
     * character (C0, DEL, C1), not a space other than ' ', not an invisible
     * format character (soft hyphen, zero-width and direction marks, byte
     * order mark), not a surrogate or a noncharacter.
     */
    bool
    is_visible(const char32_t point)
    {
      const std::pair<char32_t, char32_t> hidden[] = {{0x0, 0x20},
                                                      {0x7f, 0xa0},
                                                      {0xad, 0xad},
                                                      {0x600, 0x605},
                                                      {0x61c, 0x61c},
                                                      {0x6dd, 0x6dd},
                                                      {0x70f, 0x70f},
                                                      {0x1680, 0x1680},
                                                      {0x180e, 0x180e},
                                                      {0x2000, 0x200f},
                                                      {0x2028, 0x202f},
                                                      {0x205f, 0x206f},
                                                      {0x3000, 0x3000},
                                                      {0xd800, 0xdfff},
                                                      {0xfeff, 0xfeff},
                                                      {0xfff9, 0xfffb},
                                                      {0xfffe, 0xffff},
                                                      {0x110000, 0xffffffff}};
      return std::none_of(std::begin(hidden),
                          std::end(hidden),
                          [point](const auto &range) {
                            return range.first <= point &&
                                   point <= range.second;
                          });
    }
  } // namespace



  std::string
  one_line_message(const std::exception &error)
  {
    std::ostringstream text;
    if (const auto *dealii_error =
          dynamic_cast<const dealii::ExceptionBase *>(&error))
      dealii_error->print_info(text);
    else
      text << error.what();

    // Runs of blanks and control characters become one blank; visible
    // characters (UTF-8) stay; anything else (an invisible character, or
    // bytes of a binary file that a parser quotes) is written as \xNN per
    // byte, so that the line is printable text.
    const std::string message = text.str();
    std::string       line;
    bool              blank = false;
    for (std::size_t i = 0; i < message.size();)
      {
        const auto [length, point] = utf8_at(message, i);
        if (length == 1 && (std::isspace(point) || std::iscntrl(point)))
          {
            blank = !line.empty();
            ++i;
            continue;
          }
        if (blank)
          line += ' ';
        blank = false;
        if (length > 0 && is_visible(point))
          {
            line.append(message, i, length);
            i += length;
            continue;
          }
        for (std::size_t k = 0; k < std::max<std::size_t>(length, 1); ++k)
          {
            char escaped[5];
            std::snprintf(escaped,
                          sizeof(escaped),
                          "\\x%02x",
                          static_cast<unsigned char>(message[i + k]));
            line += escaped;
          }
        i += std::max<std::size_t>(length, 1);
      }
    return line;
  }



  std::string
  unreadable_file(const std::string &file_name)
  {
    std::error_code error;
    const auto      status = std::filesystem::status(file_name, error);
    if (status.type() == std::filesystem::file_type::not_found)
      return "no such file";
    if (error)
      return error.message();
    if (status.type() != std::filesystem::file_type::regular)
      return "not a regular file";
    return "";
  }



  namespace
  {
    using boost::property_tree::ptree;

    /** A subsection path, and optionally an entry in it, as `A/B/entry`. */
    std::string
    joined(std::vector<std::string> path, const std::string &name = "")
    {
      if (!name.empty())
        path.push_back(name);
      std::string text;
      for (const std::string &part : path)
        text += (text.empty() ? "" : "/") + part;
      return text;
    }

    /**
     * The parameters of @p prm as it holds them: a tree whose nodes are the
     * subsections and the entries, in declaration order; an entry has the
     * children `value`, `pattern_description`, ... (deal.II's JSON
     * description of the parameters).
     */
    ptree
    tree_of(const ParameterHandler &prm)
    {
      std::stringstream json;
      prm.print_parameters(json,
                           ParameterHandler::OutputStyle(
                             ParameterHandler::JSON |
                             ParameterHandler::KeepDeclarationOrder));
      ptree tree;
      boost::property_tree::read_json(json, tree);
      return tree;
    }

    /** The declared parameters, with their defaults (see tree_of()). */
    ptree
    declarations()
    {
      ParameterHandler prm;
      All::declare_parameters(prm);
      return tree_of(prm);
    }

    /** Whether @p node of declarations() is an entry, not a subsection. */
    bool
    is_entry(const ptree &node)
    {
      return node.count("pattern_description") > 0;
    }

    /** The entries (or the subsections) in @p node, as `a, b, c`. */
    std::string
    names_in(const ptree &node, const bool entries)
    {
      std::string text;
      for (const auto &[name, child] : node)
        if (is_entry(child) == entries)
          text += (text.empty() ? "" : ", ") + name;
      return text;
    }

    /**
     * Why `path/name = value` cannot be set in @p declared: a subsection of
     * @p path that is not declared, an entry that is not, or a value that
     * the entry's pattern does not match; an empty string if it can be.
     * Without @p name, only @p path is checked.
     */
    std::string
    wrong_assignment(const ptree                    &declared,
                     const std::vector<std::string> &path,
                     const std::string              &name  = "",
                     const std::string              &value = "")
    {
      const ptree *node = &declared;
      for (std::size_t depth = 0; depth < path.size(); ++depth)
        {
          const auto subsection = node->find(path[depth]);
          if (subsection == node->not_found() || is_entry(subsection->second))
            {
              const std::vector<std::string> parent(path.begin(),
                                                    path.begin() + depth);
              const std::string              known = names_in(*node, false);
              return joined(parent, path[depth]) + " is not a subsection: " +
                     (known.empty() ?
                        joined(parent) + " has no subsections" :
                        "the subsections" +
                          (parent.empty() ? "" : " of " + joined(parent)) +
                          " are " + known);
            }
          node = &subsection->second;
        }
      if (name.empty())
        return "";
      const auto entry = node->find(name);
      if (entry == node->not_found() || !is_entry(entry->second))
        return joined(path, name) + " is not a parameter: " +
               (path.empty() ? "entries are set inside the subsections " +
                                 names_in(declared, false) :
                               "the entries of " + joined(path) + " are " +
                                 names_in(*node, true));
      const auto pattern =
        entry->second.get<std::string>("pattern_description");
      if (!dealii::Patterns::pattern_factory(pattern)->match(value))
        return invalid_entry(joined(path, name), value, "expected " + pattern)
          .what();
      return "";
    }


    /**
     * What follows @p keyword (in lower case or in capitals, as deal.II
     * reads it) at the start of @p statement, if it starts with it.
     */
    std::optional<std::string>
    after_keyword(const std::string &statement, std::string keyword)
    {
      for (int capitals = 0; capitals < 2; ++capitals)
        {
          if (statement.rfind(keyword, 0) == 0)
            return trim(statement.substr(keyword.size()));
          for (char &c : keyword)
            c = static_cast<char>(std::toupper(c));
        }
      return std::nullopt;
    }

    /**
     * A statement of a parameter file as deal.II's parser sees it: the line
     * where it starts, and its text, the lines from there on joined while
     * they end in '\\', without the comment ('#' on), tabs and margins.
     */
    struct Statement
    {
      unsigned int line;
      std::string  text;
    };

    /** The statements of the parameter file @p file_name. */
    std::vector<Statement>
    statements(const std::string &file_name)
    {
      std::ifstream          in(file_name);
      std::vector<Statement> result;
      std::string            line, text;
      unsigned int           start = 1;
      for (unsigned int number = 1; std::getline(in, line); ++number)
        {
          line                 = trim(line);
          const bool continued = !line.empty() && line.back() == '\\';
          text += continued ? line.substr(0, line.size() - 1) : line;
          if (continued)
            continue;
          text = text.substr(0, text.find('#'));
          std::replace(text.begin(), text.end(), '\t', ' ');
          result.push_back({start, trim(text)});
          text.clear();
          start = number + 1;
        }
      return result;
    }

    /**
     * `file, line N: why` if the scene @p file_name includes itself, directly
     * or through other files (deal.II's parser would recurse until the
     * stack overflows), or nests includes deeper than 16 files; an empty
     * string otherwise. @p open holds the files being read, outermost
     * first.
     */
    std::string
    include_cycle(const std::string &file_name, std::vector<std::string> open)
    {
      std::error_code error;
      open.push_back(
        std::filesystem::weakly_canonical(file_name, error).string());
      for (const Statement &statement : statements(file_name))
        if (const auto included = after_keyword(statement.text, "include "))
          {
            const std::string at = file_name + ", line " +
                                   std::to_string(statement.line) +
                                   ": 'include " + *included + "' ";
            if (std::find(open.begin(),
                          open.end(),
                          std::filesystem::weakly_canonical(*included, error)
                            .string()) != open.end())
              return at + "includes a file that is being read: an include "
                          "cycle";
            if (open.size() >= 16)
              return at + "nests includes more than 16 files deep";
            if (const std::string cycle = include_cycle(*included, open);
                !cycle.empty())
              return cycle;
          }
      return "";
    }

    /**
     * The subsections of the parameter file @p file_name that are open at
     * the statement that starts on line @p line (at the end of the file if
     * none does), each with the line that opens it, and that statement.
     * deal.II's parser has accepted every statement before it: its
     * `subsection` and `end` statements are well formed.
     */
    std::pair<std::vector<Statement>, std::string>
    context(const std::string &file_name, const unsigned int line)
    {
      std::vector<Statement> open;
      for (const Statement &statement : statements(file_name))
        if (statement.line == line)
          return {open, statement.text};
        else if (const auto name = after_keyword(statement.text, "subsection "))
          open.push_back({statement.line, *name});
        else if (after_keyword(statement.text, "end") && !open.empty())
          open.pop_back();
      return {open, ""};
    }

    /** The names of @p open, the path of the innermost one. */
    std::vector<std::string>
    names_of(const std::vector<Statement> &open)
    {
      std::vector<std::string> path;
      for (const Statement &subsection : open)
        path.push_back(subsection.text);
      return path;
    }

    /**
     * The error of deal.II's parser in the statement @p statement on line
     * @p line of @p file_name, the subsections @p path open there, said in
     * the terms of the scene: a subsection or an entry that is not declared
     * with those that are, a value with the pattern it does not match (all
     * by wrong_assignment(), as for --set); otherwise deal.II's @p reason,
     * with the subsection.
     */
    std::string
    statement_error(const std::string       &file_name,
                    const unsigned int       line,
                    std::vector<std::string> path,
                    const std::string       &statement,
                    const std::string       &reason)
    {
      const std::string at =
        file_name + ", line " + std::to_string(line) + ": ";
      const ptree declared = declarations();
      if (const auto name = after_keyword(statement, "subsection "))
        {
          path.push_back(*name);
          if (const std::string error = wrong_assignment(declared, path);
              !error.empty())
            return at + error;
          path.pop_back();
        }
      const auto assignment = after_keyword(statement, "set ");
      if (assignment && assignment->find('=') != std::string::npos)
        {
          const auto equal = assignment->find('=');
          if (const std::string error =
                wrong_assignment(declared,
                                 path,
                                 trim(assignment->substr(0, equal)),
                                 trim(assignment->substr(equal + 1)));
              !error.empty())
            return at + error;
        }
      return at + (path.empty() ? "" : "in subsection " + joined(path) + ": ") +
             reason;
    }

    /**
     * The line and the reason of deal.II's message @p message, `Line <N> of
     * file <F>: why` (`<F: why` when a subsection is not declared), if F is
     * @p file_name.
     */
    std::optional<std::pair<unsigned int, std::string>>
    located(const std::string &message, const std::string &file_name)
    {
      const std::string start = "Line <";
      const std::size_t end   = message.find('>');
      if (message.rfind(start, 0) != 0 || end == std::string::npos ||
          end == start.size() || end > start.size() + 9 ||
          message.find_first_not_of("0123456789", start.size()) != end)
        return std::nullopt;
      for (const std::string &file : {"> of file <" + file_name + ">: ",
                                      "> of file <" + file_name + ": "})
        if (message.compare(end, file.size(), file) == 0)
          return std::pair{static_cast<unsigned int>(std::stoul(
                             message.substr(start.size(), end - start.size()))),
                           message.substr(end + file.size())};
      return std::nullopt;
    }

    /**
     * The one-line message for the error @p error of deal.II's parser in
     * the scene @p file_name. For an error in the scene itself (not in a
     * file that it includes, where the subsections open at the include
     * would be missing), the statement on the line that deal.II names is
     * read again for statement_error(), and a subsection without `end` is
     * named with its line; otherwise the message is deal.II's.
     */
    std::string
    scene_error(const dealii::ExceptionBase &error,
                const std::string           &file_name)
    {
      const std::string message = one_line_message(error);
      if (dynamic_cast<const ParameterHandler::ExcUnbalancedSubsections *>(
            &error) &&
          message.find("parameter file <" + file_name + ">") !=
            std::string::npos)
        {
          // Line 0 is before the first statement: the end of the file.
          const auto open = context(file_name, 0).first;
          if (!open.empty())
            return file_name + ", line " + std::to_string(open.back().line) +
                   ": subsection " + joined(names_of(open)) +
                   " has no 'end' before the end of the file";
        }
      if (const auto line_and_reason = located(message, file_name))
        {
          const auto &[line, reason]   = *line_and_reason;
          const auto [open, statement] = context(file_name, line);
          return statement_error(
            file_name, line, names_of(open), statement, reason);
        }
      return file_name + ": " + message;
    }
  } // namespace



  void
  read_scene(ParameterHandler &prm, const std::string &file_name)
  {
    if (const std::string problem = unreadable_file(file_name);
        !problem.empty())
      throw InputError(file_name + ": " + problem +
                       "; a scene is a parameter file 'name.prm'");
    if (const std::string cycle = include_cycle(file_name, {}); !cycle.empty())
      throw InputError(cycle);
    try
      {
        prm.parse_input(file_name, "", false, false);
      }
    catch (const dealii::ExceptionBase &e)
      {
        throw InputError(scene_error(e, file_name));
      }
  }



  void
  set_entry(ParameterHandler &prm, const std::string &assignment)
  {
    const auto        equal = assignment.find('=');
    const auto        slash = assignment.rfind('/', equal);
    const std::string entry =
      slash == std::string::npos ?
        "" :
        trim(assignment.substr(slash + 1, equal - slash - 1));
    if (equal == std::string::npos || entry.empty())
      throw InputError("--set '" + assignment +
                       "': expected 'Subsection/Entry=value'");
    const auto subsections =
      dealii::Utilities::split_string_list(assignment.substr(0, slash), '/');
    const std::string value = trim(assignment.substr(equal + 1));
    if (const std::string error =
          wrong_assignment(declarations(), subsections, entry, value);
        !error.empty())
      throw InputError("--set '" + assignment + "': " + error);
    for (const auto &subsection : subsections)
      prm.enter_subsection(subsection);
    prm.set(entry, value);
    for (unsigned int i = 0; i < subsections.size(); ++i)
      prm.leave_subsection();
  }



  namespace
  {
    /**
     * The first entry of @p tree (of tree_of()) below the subsections
     * @p path whose value a parameter file cannot hold (see
     * parameter_file()), as `Subsection/Entry` and its value; empty if there
     * is none.
     */
    std::pair<std::string, std::string>
    first_unwritable(const ptree                    &tree,
                     const std::vector<std::string> &path = {})
    {
      for (const auto &[name, node] : tree)
        if (is_entry(node))
          {
            const auto value = node.get<std::string>("value");
            if (value.find_first_of("#\n\r") != std::string::npos ||
                (!value.empty() && value.back() == '\\'))
              return {joined(path, name), value};
          }
        else
          {
            std::vector<std::string> below = path;
            below.push_back(name);
            if (auto found = first_unwritable(node, below);
                !found.first.empty())
              return found;
          }
      return {};
    }

    /** Every entry of @p tree below @p path: (`A/B/entry`, value). */
    void
    entries_of(const ptree                                      &tree,
               const std::vector<std::string>                   &path,
               std::vector<std::pair<std::string, std::string>> &entries)
    {
      for (const auto &[name, node] : tree)
        if (is_entry(node))
          entries.emplace_back(joined(path, name),
                               node.get<std::string>("value"));
        else
          {
            std::vector<std::string> below = path;
            below.push_back(name);
            entries_of(node, below, entries);
          }
    }

    /** The entries of the parameter file @p text (of parameter_file()). */
    std::vector<std::pair<std::string, std::string>>
    entries_of(const std::string &text)
    {
      ParameterHandler prm;
      All::declare_parameters(prm);
      prm.parse_input_from_string(text);
      std::vector<std::pair<std::string, std::string>> entries;
      entries_of(tree_of(prm), {}, entries);
      return entries;
    }
  } // namespace



  std::string
  first_difference(const std::string              &recorded,
                   const std::string              &current,
                   const std::vector<std::string> &free)
  {
    const auto before = entries_of(recorded);
    const auto now    = entries_of(current);
    for (unsigned int i = 0; i < before.size() && i < now.size(); ++i)
      if (std::find(free.begin(), free.end(), now[i].first) == free.end() &&
          before[i] != now[i])
        return "'" + now[i].first + "' is '" + now[i].second +
               "' here and was '" + before[i].second + "'";
    return "";
  }



  std::string
  parameter_file(const ParameterHandler &prm)
  {
    const auto [entry, value] = first_unwritable(tree_of(prm));
    if (!entry.empty())
      throw invalid_entry(entry,
                          value,
                          "parameters.prm, the record of the run, cannot "
                          "hold a line break, a '#' (a comment starts there) "
                          "or a '\\' at the end of a value");
    std::ostringstream text;
    prm.print_parameters(text, ParameterHandler::PRM);
    return text.str();
  }
} // namespace membranes::Parameters
