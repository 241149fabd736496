#include "capture/rig_text.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "capture/camera_model.h"
#include "tests/common/test_data.h"

namespace orthoface::capture {
namespace {

namespace fs = std::filesystem;

// The message parse_rig_text gives for `text`, or "parsed".
std::string refusal(const std::string& text) {
  try {
    parse_rig_text(text);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "parsed";
}

// Nodes of every kind rig files hold, written by OpenCV itself in `ext` (.yaml / .xml).
std::string written_by_opencv(const fs::path& dir, const std::string& ext) {
  const std::string path = (dir / ("opencv" + ext)).string();
  cv::FileStorage out(path, cv::FileStorage::WRITE);
  out << "version" << 1 << "negative" << -7 << "source"
      << "rig of bay 2";
  out << "camera"
      << "{";
  out << "projection"
      << "perspective"
      << "camera_matrix" << (cv::Mat_<double>(3, 3) << 1600.5, 0, 320, 0, 1.6e-3, 240, 0, 0, 1);
  out << "floats" << (cv::Mat_<float>(1, 4) << 0.25f, -1.5f, 3e7f, 0);
  out << "}";
  out << "image_size" << cv::Size(640, 480);
  out << "names"
      << "["
      << "front"
      << "side"
      << "]";
  out.release();
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

TEST(RigText, ReadsWhatOpenCvWritesInYamlAndXml) {
  const fs::path dir = testing::temp_dir("rig_text_opencv");
  for (const std::string ext : {".yaml", ".xml"}) {
    SCOPED_TRACE(ext);
    const RigNode root = parse_rig_text(written_by_opencv(dir, ext));
    ASSERT_TRUE(root.is_map());
    ASSERT_NE(root.find("version"), nullptr);
    EXPECT_EQ(root.find("version")->as_int(), 1);
    EXPECT_EQ(root.find("negative")->as_int(), -7);
    EXPECT_EQ(root.find("source")->text, "rig of bay 2");
    const RigNode* camera = root.find("camera");
    ASSERT_NE(camera, nullptr);
    ASSERT_TRUE(camera->is_map());
    EXPECT_EQ(camera->find("projection")->text, "perspective");
    const cv::Mat k = matrix_from_node(*camera->find("camera_matrix"));
    ASSERT_EQ(k.size(), cv::Size(3, 3));
    EXPECT_EQ(k.at<double>(0, 0), 1600.5);
    EXPECT_EQ(k.at<double>(1, 1), 1.6e-3);
    EXPECT_EQ(k.at<double>(1, 2), 240);
    const cv::Mat f = matrix_from_node(*camera->find("floats"));
    ASSERT_EQ(f.size(), cv::Size(4, 1));
    EXPECT_EQ(f.at<double>(1), -1.5);
    EXPECT_EQ(f.at<double>(2), 3e7);
    const RigNode* size = root.find("image_size");
    ASSERT_TRUE(size && size->is_seq());
    ASSERT_EQ(size->items.size(), 2u);
    EXPECT_EQ(size->items[0].as_int(), 640);
    EXPECT_EQ(size->items[1].as_int(), 480);
    const RigNode* names = root.find("names");
    ASSERT_TRUE(names && names->is_seq());
    EXPECT_EQ(names->items[1].text, "side");
    EXPECT_EQ(root.find("absent"), nullptr);
  }
}

TEST(RigText, ReadsTheHandWrittenYamlForms) {
  const RigNode root = parse_rig_text(
      "# a rig written by hand\n"
      "%YAML 1.2\n"
      "--- # the one document\n"
      "a: 1   # a comment after a value\n"
      "b: \"text with # and \\\"quotes\\\"\"\n"
      "c: 'it''s'\n"
      "flow: { x: 1, y: [ 2, 3 ], 'z': -.inf }\n"
      "list:\n"
      "- 4\n"
      "- [ 5, 6 ]\n"
      "nested:\n"
      "    inner: !custom\n"
      "        - 7\n"
      "        -\n"
      "            deep: 8\n"
      "empty:\n"
      "url: http://host:8080/x\n"
      "...\n"
      "ignored after the end: 1\n");
  EXPECT_EQ(root.find("a")->as_int(), 1);
  EXPECT_EQ(root.find("b")->text, "text with # and \"quotes\"");
  EXPECT_TRUE(root.find("b")->quoted);
  EXPECT_EQ(root.find("c")->text, "it's");
  const RigNode* flow = root.find("flow");
  ASSERT_TRUE(flow && flow->is_map());
  EXPECT_EQ(flow->find("y")->items[1].as_int(), 3);
  EXPECT_EQ(flow->find("z")->as_number(), -INFINITY);
  const RigNode* list = root.find("list");
  ASSERT_TRUE(list && list->is_seq());
  ASSERT_EQ(list->items.size(), 2u);
  EXPECT_EQ(list->items[1].items[0].as_int(), 5);
  const RigNode* inner = root.find("nested")->find("inner");
  ASSERT_TRUE(inner && inner->is_seq());
  EXPECT_EQ(inner->tag, "custom");
  EXPECT_EQ(inner->items[1].find("deep")->as_int(), 8);
  EXPECT_EQ(inner->items[1].find("deep")->line, 15);
  EXPECT_TRUE(root.find("empty")->is_scalar());
  EXPECT_EQ(root.find("empty")->text, "");
  EXPECT_EQ(root.find("url")->text, "http://host:8080/x");
  EXPECT_EQ(root.find("ignored after the end"), nullptr);
  EXPECT_TRUE(parse_rig_text("").is_map());
  EXPECT_TRUE(parse_rig_text("%YAML:1.0\n---\n").is_map());
  EXPECT_EQ(parse_rig_text("{ a: 1 }").find("a")->as_int(), 1);
  EXPECT_EQ(parse_rig_text("a: 1\r\nb: 2\r\n").find("b")->as_int(), 2);
}

TEST(RigText, ReadsXmlWithCommentsEntitiesAndSequences) {
  const RigNode root = parse_rig_text(
      "<?xml version=\"1.0\"?>\n<!-- rig -->\n<opencv_storage>\n"
      "<name>a&amp;b</name>\n<quoted>\"two words\"</quoted>\n"
      "<K1 type_id=\"opencv-matrix\"><rows>1</rows><cols>1</cols><dt>d</dt>"
      "<data>\n  2.5</data></K1>\n"
      "<seq><_>1</_><_><x>2</x></_></seq>\n<empty/>\n</opencv_storage>\n");
  EXPECT_EQ(root.find("name")->text, "a&b");
  EXPECT_EQ(root.find("quoted")->text, "two words");
  EXPECT_EQ(root.find("K1")->tag, "opencv-matrix");
  EXPECT_EQ(matrix_from_node(*root.find("K1")).at<double>(0), 2.5);
  const RigNode* seq = root.find("seq");
  ASSERT_TRUE(seq && seq->is_seq());
  EXPECT_EQ(seq->items[1].find("x")->as_int(), 2);
  EXPECT_EQ(root.find("empty")->text, "");
}

TEST(RigText, NumbersAreReadAsYamlAndOpenCvWriteThem) {
  auto scalar = [](const std::string& text, bool quoted = false) {
    RigNode n;
    n.text = text;
    n.quoted = quoted;
    return n;
  };
  EXPECT_EQ(scalar("640").as_int(), 640);
  EXPECT_EQ(scalar("+3").as_int(), 3);
  EXPECT_EQ(scalar("-2").as_int(), -2);
  for (const char* not_int : {"3.0", "1e3", "2147483648", "0x10", "12px", "", " 1"})
    EXPECT_FALSE(scalar(not_int).as_int()) << not_int;
  EXPECT_FALSE(scalar("5", true).as_int());
  EXPECT_EQ(scalar("0.").as_number(), 0.0);
  EXPECT_EQ(scalar(".5").as_number(), 0.5);
  EXPECT_EQ(scalar("-1.6000000000000001e+00").as_number(), -1.6000000000000001);
  EXPECT_EQ(scalar("+2").as_number(), 2.0);
  EXPECT_EQ(scalar("-.Inf").as_number(), -INFINITY);
  EXPECT_EQ(scalar("1e999").as_number(), INFINITY);
  EXPECT_TRUE(std::isnan(*scalar(".nan").as_number()));
  for (const char* not_number : {"abc", "nan", "inf", "1.5.2", "--1", "1,5", "e5", "", "0x1p3"})
    EXPECT_FALSE(scalar(not_number).as_number()) << not_number;
  EXPECT_FALSE(scalar("2.5", true).as_number());
  RigNode seq;
  seq.kind = RigNode::Kind::Seq;
  EXPECT_FALSE(seq.as_number());
  EXPECT_EQ(seq.find("a"), nullptr);
}

TEST(RigText, MalformedTextIsRefusedNamingTheLine) {
  const std::pair<std::string, std::string> cases[] = {
      {"a: 1\n\tb: 2\n", "line 2: a tab in the indentation"},
      {"a: 1\na: 2\n", "line 2: key 'a' given twice"},
      {"a: 1\n---\nb: 2\n", "line 2: a second document"},
      {"a: 1\n%TAG ! x\n", "line 2: a directive after"},
      {"a: \"open\n", "line 1: a quoted text is not closed"},
      {"D1:\n   rows: 1\n   cols: cols: 3\n", "line 3: a mapping inside a value"},
      {"a:\n  b: 1\n    c: 2\n", "line 3: indented more than the key"},
      {"  a: 1\nb: 2\n", "line 2: indented less than the document's first key"},
      {"a: [ \"x\" 1 ]\n", "line 1: expected ',' or ']'"},
      {"a: [ 1, 2,\n", "line 1: a '[' or '{' is never closed"},
      {"a: [ 1, , 2 ]\n", "line 1: an empty value"},
      {"a: { b 1 }\n", "line 1: expected ':' after the key 'b 1'"},
      {"a: ]\n", "line 1: a bracket inside a plain value"},
      {"a: [ 1 ] x\n", "line 1: unexpected text 'x'"},
      {"- 1\n- 2\n", "line 1: the document is a sequence"},
      {"a: 1\n- 2\n", "line 2: a sequence item among the keys"},
      {"just text\n", "line 1: expected 'key: value', got 'just text'"},
      {"a: !! 1\n", "line 1: an empty tag"},
      {"a: \"\\q\"\n", "line 1: unknown escape"},
      {"a: 1\nb: \x01\n", "line 2: byte 0x01 at offset 8"},
      {"a: " + std::string(9, '[') + "1" + std::string(9, ']'), "line 1: nested more than 8"},
      {"<r><a>1</b></r>", "line 1: <a> is closed by </b>"},
      {"<r>\n<a>1<b>2</b></a></r>", "line 2: <a> mixes text and elements"},
      {"<r><a>&bogus;</a></r>", "an unknown entity '&bogus;'"},
      {"<r><a>1</a>", "<r> is never closed"},
      {"<r><_>1</_><a>2</a></r>", "mixes sequence items"},
      {"<r><a>1</a><a>2</a></r>", "key 'a' given twice"},
      {"<r><a x=1>1</a></r>", "an attribute value must be quoted"},
      {"<r><![CDATA[x]]></r>", "CDATA"},
      {"<r>1</r>", "does not hold named elements"},
      {"<r/> trailing", "text after the root element"},
  };
  for (const auto& [text, expect] : cases)
    EXPECT_NE(refusal(text).find(expect), std::string::npos)
        << "text: " << text << "\nmessage: " << refusal(text);
  std::string deep_block = "a0:\n";
  for (int i = 1; i < 10; ++i)
    deep_block += std::string(size_t(i) * 2, ' ') + "a" + std::to_string(i) + ":\n";
  EXPECT_NE(refusal(deep_block).find("nested more than 8 deep"), std::string::npos)
      << refusal(deep_block);
  std::string deep_xml;
  for (int i = 0; i < 9; ++i) deep_xml += "<a" + std::to_string(i) + ">";
  EXPECT_NE(refusal(deep_xml).find("nested more than 8 deep"), std::string::npos);
  EXPECT_NE(refusal(std::string(kMaxRigBytes + 1, ' ')).find("over 1 MiB"), std::string::npos);
}

TEST(RigText, MatrixNodesAreCheckedBeforeAnythingIsAllocated) {
  const RigNode root = parse_rig_text(
      "big: !!opencv-matrix\n   rows: 100000\n   cols: 100000\n   dt: d\n   data: [ 1. ]\n"
      "short: !!opencv-matrix\n   rows: 2\n   cols: 2\n   dt: d\n   data: [ 1., 2., 3. ]\n"
      "channels: !!opencv-matrix\n   rows: 1\n   cols: 1\n   dt: 3d\n   data: [ 1., 2., 3. ]\n"
      "word: !!opencv-matrix\n   rows: 1\n   cols: 2\n   dt: f\n   data: [ 1., x ]\n"
      "tagged: !!opencv-nd-matrix\n   rows: 1\n   cols: 1\n   data: [ 1. ]\n"
      "unsized: !!opencv-matrix\n   rows: 1.5\n   cols: 1\n   data: [ 1. ]\n"
      "text: [ 1, 2 ]\n"
      "ok: !!opencv-matrix\n   rows: 2\n   cols: 2\n   dt: d\n   data: [ 1., 2., 3., .nan ]\n");
  const std::pair<const char*, const char*> cases[] = {
      {"big", "is 100000 x 100000"},  {"short", "needs 4 data values (rows x cols), has 3"},
      {"channels", "one channel"},    {"word", "data value 2 'x' is not a number"},
      {"tagged", "opencv-nd-matrix"}, {"unsized", "whole numbers for rows and cols"},
      {"text", "is not a matrix"},
  };
  for (const auto& [key, expect] : cases) {
    try {
      matrix_from_node(*root.find(key));
      ADD_FAILURE() << key << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(expect), std::string::npos) << key << ": " << e.what();
    }
  }
  const cv::Mat ok = matrix_from_node(*root.find("ok"));
  EXPECT_EQ(ok.type(), CV_64F);
  EXPECT_EQ(ok.at<double>(1, 0), 3.0);
  EXPECT_TRUE(std::isnan(ok.at<double>(1, 1)));  // finiteness is the caller's to judge
}

TEST(RigText, ReadRigTextNamesTheFile) {
  const fs::path dir = testing::temp_dir("rig_text_files");
  auto message = [](const std::string& path) {
    try {
      read_rig_text(path);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("read");
  };
  EXPECT_EQ(message((dir / "none.yaml").string()),
            "rig file " + (dir / "none.yaml").string() + ": no such file");
  EXPECT_NE(message(dir.string()).find("no such file"), std::string::npos);
  std::ofstream(dir / "bad.yaml") << "a: 1\nb c\n";
  EXPECT_EQ(message((dir / "bad.yaml").string()), "rig file " + (dir / "bad.yaml").string() +
                                                      ": line 2: expected 'key: value', got 'b c'");
  std::ofstream(dir / "good.yaml") << "a: 1\n";
  EXPECT_EQ(read_rig_text((dir / "good.yaml").string()).find("a")->as_int(), 1);
}

TEST(RigText, WritesXmlOrYamlByExtensionAllOrNothing) {
  const fs::path dir = testing::temp_dir("rig_text_write");
  for (const std::string name : {"rig.xml", "rig.YAML", "rig.yml"}) {
    const std::string path = (dir / name).string();
    write_rig_text(path, [](cv::FileStorage& fs) {
      fs << "a" << 1 << "b"
         << "two words";
    });
    std::ifstream in(path);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_EQ(text.rfind(name == "rig.xml" ? "<?xml" : "%YAML", 0), 0u) << name << ": " << text;
    const RigNode root = parse_rig_text(text);
    EXPECT_EQ(root.find("a")->as_int(), 1);
    EXPECT_EQ(root.find("b")->text, "two words");
  }
  // A full disk (here a 512-byte file size limit) fails the write, naming the file, and leaves
  // the rig that was there.
  const std::string path = (dir / "kept.yaml").string();
  write_rig(ideal_rig(64, 48, 1.0), path);
  std::ifstream before_in(path);
  const std::string before((std::istreambuf_iterator<char>(before_in)),
                           std::istreambuf_iterator<char>());
  const pid_t child = fork();
  if (child == 0) {
    signal(SIGXFSZ, SIG_IGN);
    const rlimit limit{512, 512};
    setrlimit(RLIMIT_FSIZE, &limit);
    try {
      write_rig(ideal_rig(640, 480, 2.0), path);
    } catch (const std::runtime_error& e) {
      _exit(std::string(e.what()).find(path) != std::string::npos ? 0 : 2);
    }
    _exit(3);
  }
  int status = 0;
  waitpid(child, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "2: the error does not name the file, 3: no error";
  std::ifstream after_in(path);
  const std::string after((std::istreambuf_iterator<char>(after_in)),
                          std::istreambuf_iterator<char>());
  EXPECT_EQ(after, before);
  for (const auto& entry : fs::directory_iterator(dir))
    EXPECT_EQ(entry.path().string().find(".tmp"), std::string::npos) << entry.path();
}

}  // namespace
}  // namespace orthoface::capture
