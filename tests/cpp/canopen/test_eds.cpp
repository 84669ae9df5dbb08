// EDS/DCF import and export.  The sample below is our own small file in the
// shape vendors ship (mixed case, $NODEID on either side, CompactSubObj).
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <fstream>

#include "motorbus/canopen/eds.hpp"
#include "test_sdo_util.hpp"

using namespace motorbus;
using namespace motorbus::canopen;
using motorbus::test::hex;

namespace {
const char* kSampleEds = R"(; a small stepper drive, written for the motorbus tests
[FileInfo]
FileName=stepper.eds
Description=Test stepper
EDSVersion=4.0

[DeviceInfo]
VendorName=Motorbus Test
VendorNumber=0x000000AB
ProductName=Stepper 42
ProductNumber=42
BaudRate_125=1
BaudRate_500=1
NrOfRXPDO=1
NrOfTXPDO=1

[DeviceComissioning]
NodeID=5

[1000]
ParameterName=Device type
ObjectType=0x7
DataType=0x0007
AccessType=ro
DefaultValue=0x00040192
PDOMapping=0

[1008]
ParameterName=Manufacturer device name
ObjectType=0x7
DataType=0x0009
AccessType=const
DefaultValue=STEPPER 42

[1018]
ParameterName=Identity object
ObjectType=0x9
SubNumber=3

[1018sub0]
ParameterName=Highest sub-index supported
ObjectType=0x7
DataType=0x0005
AccessType=const
DefaultValue=2

[1018sub1]
ParameterName=Vendor-ID
ObjectType=0x7
DataType=0x0007
AccessType=ro
DefaultValue=0xAB

[1018Sub2]
ParameterName=Product code
ObjectType=0x7
DataType=0x0007
AccessType=ro
DefaultValue=42

[1800]
ParameterName=TPDO1 communication parameter
ObjectType=9
SubNumber=2

[1800sub0]
ParameterName=Highest sub-index supported
ObjectType=7
DataType=5
AccessType=ro
DefaultValue=1

[1800sub1]
ParameterName=COB-ID
ObjectType=7
DataType=7
AccessType=rw
DefaultValue=$NODEID+0x180

[1a00]
ParameterName=TPDO1 mapping
ObjectType=0x9
SubNumber=2

[1a00sub0]
ParameterName=Number of mapped objects
ObjectType=0x7
DataType=0x0005
AccessType=rw
DefaultValue=1
LowLimit=0
HighLimit=8

[1A00sub1]
ParameterName=Mapping 1
ObjectType=0x7
DataType=0x0007
AccessType=rw
DefaultValue=0x60640020

[2003]
ParameterName=Baud index
ObjectType=0x7
DataType=0x0005
AccessType=RW
DefaultValue=4
LowLimit=0
HighLimit=8
PDOMapping=0

[2010]
ParameterName=Gain
ObjectType=0x7
DataType=0x0008
AccessType=rw
DefaultValue=1.25
LowLimit=0.5

[2020]
ParameterName=Sensor
ObjectType=8
CompactSubObj=3
DataType=0x0003
AccessType=ro
DefaultValue=-7
PDOMapping=1

[2020Name]
NrOfEntries=2
1=Left
2=Right

[2030]
ParameterName=Vendor blob
ObjectType=0x7
DataType=0x0040
AccessType=rw

[6064]
ParameterName=Position actual value
ObjectType=0x7
DataType=0x0004
AccessType=ro
PDOMapping=1
DefaultValue=0
ParameterValue=-1000
)";
}  // namespace

TEST(Eds, ImportsVendorShapes) {
    std::vector<std::string> warnings;
    auto od = parse_eds(kSampleEds, {}, &warnings);
    EXPECT_EQ(od->node_id(), 5);
    EXPECT_EQ(od->device_info().vendor_name, "Motorbus Test");
    EXPECT_EQ(od->device_info().vendor_number, 0xABu);
    EXPECT_EQ(od->device_info().baud_rates_kbit, (std::vector<unsigned>{125, 500}));
    EXPECT_EQ(od->at(0x1000, 0)->get_u64(), 0x40192u);
    EXPECT_EQ(od->at("Manufacturer device name")->get_string(), "STEPPER 42");
    EXPECT_EQ(od->at("Identity object.Product code")->get_u64(), 42u);  // [1018Sub2], mixed case
    EXPECT_EQ(od->at(0x1800, 1)->get_u64(), 0x185u);                    // $NODEID+0x180, node 5
    EXPECT_EQ(od->at(0x1800, 1)->spec().default_expr, "$NODEID+0x180");
    EXPECT_EQ(od->at(0x1A00, 1)->get_u64(), 0x60640020u);               // [1A00sub1] vs [1a00]
    auto baud = od->at("Baud index");
    EXPECT_EQ(baud->access(), Access::RW);
    EXPECT_EQ(baud->remote_write(Bytes{9}), abort_code::kValueTooHigh);
    EXPECT_DOUBLE_EQ(od->at(0x2010, 0)->get_f64(), 1.25);
    EXPECT_EQ(od->at(0x2010, 0)->remote_write(*encode_scalar(DataType::Real32, 0.25)), abort_code::kValueTooLow);
    // CompactSubObj array: names from [2020Name], the third falls back to "<name> 3".
    EXPECT_EQ(od->at(0x2020, 0)->get_u64(), 3u);
    EXPECT_EQ(od->at("Sensor.Left")->get_i64(), -7);
    EXPECT_EQ(od->at(0x2020, 3)->name(), "Sensor 3");
    EXPECT_TRUE(od->at(0x2020, 2)->pdo_mappable());
    // DCF ParameterValue is the current value; DefaultValue stays the default.
    EXPECT_EQ(od->at(0x6064, 0)->get_i64(), -1000);
    od->at(0x6064, 0)->reset_to_default();
    EXPECT_EQ(od->at(0x6064, 0)->get_i64(), 0);
    // Unknown data type 0x40 is skipped and reported, not guessed.
    EXPECT_EQ(od->find(0x2030, 0), nullptr);
    ASSERT_EQ(warnings.size(), 1u);
    EXPECT_NE(warnings[0].find("[2030]"), std::string::npos);
}

TEST(Eds, NodeIdOptionOverridesCommissioning) {
    EdsImportOptions o;
    o.node_id = 0x20;
    auto od = parse_eds(kSampleEds, o);
    EXPECT_EQ(od->at(0x1800, 1)->get_u64(), 0x1A0u);
}

TEST(Eds, ExportRoundTrips) {
    auto od = parse_eds(kSampleEds);
    od->at(0x2003, 0)->set_u64(7);
    std::string text = to_eds(*od, {.dcf = true});
    EXPECT_NE(text.find("[1800sub1]"), std::string::npos);
    EXPECT_NE(text.find("DefaultValue=$NODEID+0x180"), std::string::npos);
    EXPECT_NE(text.find("[ManufacturerObjects]\nSupportedObjects=3\n1=0x2003\n2=0x2010\n3=0x2020"),
              std::string::npos);
    auto back = parse_eds(text);
    ASSERT_EQ(back->indices(), od->indices());
    for (auto i : od->indices()) {
        auto a = od->object(i), b = back->object(i);
        ASSERT_TRUE(b);
        EXPECT_EQ(a->name, b->name);
        EXPECT_EQ(a->code, b->code);
        ASSERT_EQ(a->subs.size(), b->subs.size()) << std::hex << i;
        for (auto& [s, va] : a->subs) {
            auto vb = b->subs.at(s);
            EXPECT_EQ(va->name(), vb->name());
            EXPECT_EQ(va->type(), vb->type());
            EXPECT_EQ(va->access(), vb->access());
            EXPECT_EQ(va->pdo_mappable(), vb->pdo_mappable());
            EXPECT_EQ(va->default_bytes(), vb->default_bytes()) << std::hex << i << ":" << int(s);
            EXPECT_EQ(va->get(), vb->get()) << std::hex << i << ":" << int(s);
            EXPECT_EQ(va->spec().low_limit.has_value(), vb->spec().low_limit.has_value());
        }
    }
    EXPECT_EQ(back->at(0x2003, 0)->get_u64(), 7u);  // ParameterValue carried the current value
}

TEST(Eds, ExpressionsAndErrors) {
    EXPECT_EQ(eval_eds_integer("$NODEID+0x180", 5), 0x185);
    EXPECT_EQ(eval_eds_integer("1280+$NODEID", 2), 1282);
    EXPECT_EQ(eval_eds_integer("$nodeid + 512", 1), 513);
    EXPECT_EQ(eval_eds_integer("-5", 0), -5);
    EXPECT_EQ(eval_eds_integer("017", 0), 15);
    EXPECT_EQ(eval_eds_integer("-0x10", 0), -16);
    EXPECT_EQ(eval_eds_integer("-010", 0), -8);
    EXPECT_EQ(eval_eds_integer("-9223372036854775808", 0), INT64_MIN);
    EXPECT_FALSE(eval_eds_integer("-9223372036854775809", 0));  // below INT64_MIN
    EXPECT_FALSE(eval_eds_integer("- 5", 0));                   // sign and digits apart
    EXPECT_FALSE(eval_eds_integer("--5", 0));
    EXPECT_FALSE(eval_eds_integer("0x", 0));
    EXPECT_FALSE(eval_eds_integer("08", 0));                    // not octal
    EXPECT_FALSE(eval_eds_integer("abc", 0));
    EXPECT_FALSE(eval_eds_integer("", 0));
    EXPECT_THROW(parse_eds("[FileInfo]\nFileName=x\n"), InvalidArgument);
    EXPECT_THROW(parse_eds("[1000\nx=1\n"), InvalidArgument);
    EXPECT_THROW(parse_eds("just text\n"), InvalidArgument);
    EXPECT_THROW(load_eds("/nonexistent/file.eds"), InvalidArgument);
}

// Hardening (defect 9): load_eds reads at most kMaxEdsFileBytes and refuses a
// bigger file with an error naming the file and the cap, without reading on.
TEST(EdsHardening, EndlessFileRefusedFastAtTheCap) {
    const auto t0 = std::chrono::steady_clock::now();
    try {
        load_eds("/dev/zero");
        FAIL() << "load_eds(/dev/zero) returned";
    } catch (const InvalidArgument& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("/dev/zero"), std::string::npos) << what;
        EXPECT_NE(what.find("16 MiB"), std::string::npos) << what;
    }
    EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(2));
    EXPECT_EQ(kMaxEdsFileBytes, std::size_t{16} << 20);
}

TEST(EdsHardening, FileJustOverTheCapRefusedAtTheCapAccepted) {
    const std::string path = ::testing::TempDir() + "/motorbus_big.eds";
    {
        std::ofstream f(path, std::ios::binary);
        std::string head = "[1000]\nParameterName=Device type\nDataType=0x0007\nAccessType=ro\nDefaultValue=0\n";
        f << head << std::string(kMaxEdsFileBytes - head.size(), ';');
    }
    EXPECT_NO_THROW(load_eds(path));  // exactly the cap: read
    {
        std::ofstream f(path, std::ios::binary | std::ios::app);
        f << ';';
    }
    EXPECT_THROW(load_eds(path), InvalidArgument);  // one byte more: refused
    std::remove(path.c_str());
}
