// The live total behind --memory-budget (issue 17 item 6): a node's scratch
// scope counts what its budget passes until the scope ends, a field handed to
// its own token counts once, the cache is asked to give room before a refusal,
// and the high-water mark sees all of it. The expected totals are sums of the
// sizes the test asks for.
#include "atlas/core/memory_ledger.h"

#include "atlas/core/error.h"

#include <gtest/gtest.h>

#include <string>

using namespace atlas;
using atlas::detail::MemoryLedger;

TEST(MemoryLedger, ScratchScopeCountsPassedChecksUntilItEnds) {
    const MemoryLedger ledger;
    const MemoryBudget cook(1000);
    const MemoryLedger::Attachment attached(cook, ledger);
    {
        const MemoryBudget node(1000);
        const MemoryLedger::ScratchScope scope(node, ledger);
        node.check(300, "a");
        node.check(500, "b");
        EXPECT_EQ(ledger.in_use(), 800u);
        EXPECT_EQ(scope.held(), 800u);
        // 800 held + 300 > 1000: refused, naming the requester and what is held.
        try {
            node.check(300, "node 'n': c");
            ADD_FAILURE() << "not refused";
        } catch (const MemoryBudgetError& e) {
            const std::string m = e.what();
            EXPECT_NE(m.find("node 'n': c"), std::string::npos) << m;
            EXPECT_NE(m.find("800 B already held"), std::string::npos) << m;
        }
        EXPECT_EQ(ledger.in_use(), 800u); // a refusal reserves nothing
        // The cook's own budget sees the node's scratch as held.
        EXPECT_THROW(cook.check(201, "d"), MemoryBudgetError);
        cook.check(200, "e"); // not scoped: checks, reserves nothing
        EXPECT_EQ(ledger.in_use(), 800u);
    }
    EXPECT_EQ(ledger.in_use(), 0u);
    EXPECT_EQ(ledger.peak(), 800u);
    ledger.reset_peak();
    EXPECT_EQ(ledger.peak(), 0u);
}

TEST(MemoryLedger, AFieldHandedToItsTokenCountsOnceAndOnlyWhileAlive) {
    const MemoryLedger ledger;
    const MemoryBudget cook(1000);
    const MemoryLedger::Attachment attached(cook, ledger);
    int field = 0; // stands for the field object (its address is the key)
    std::shared_ptr<void> token;
    {
        const MemoryBudget node(1000);
        const MemoryLedger::ScratchScope scope(node, ledger);
        node.check(400, "field"); // the field's constructor checks
        token = detail::hold_against(node, &field, 400);
        ASSERT_TRUE(token);
        EXPECT_EQ(ledger.in_use(), 400u);
        EXPECT_EQ(scope.held(), 0u);
        node.check(100, "temporary");
        EXPECT_EQ(ledger.in_use(), 500u);
        // The same object again (a value and the cache sharing it) counts once.
        EXPECT_FALSE(ledger.hold(&field, 400));
    }
    EXPECT_EQ(ledger.in_use(), 400u); // the output outlives the node
    token.reset();
    EXPECT_EQ(ledger.in_use(), 0u);
    EXPECT_EQ(ledger.peak(), 500u);
}

TEST(MemoryLedger, TheEvictorIsAskedForTheMissingBytesBeforeARefusal) {
    const MemoryLedger ledger;
    const MemoryBudget cook(1000);
    const MemoryLedger::Attachment attached(cook, ledger);
    int cached = 0;
    std::shared_ptr<void> entry = ledger.hold(&cached, 700);
    uint64_t asked = 0;
    ledger.set_evictor([&](uint64_t missing) {
        asked = missing;
        entry.reset();
    });
    const MemoryBudget node(1000);
    const MemoryLedger::ScratchScope scope(node, ledger);
    node.check(600, "needs room");
    EXPECT_EQ(asked, 300u); // 700 + 600 - 1000
    EXPECT_EQ(ledger.in_use(), 600u);
    // Nothing left to evict: refused.
    EXPECT_THROW(node.check(600, "too much"), MemoryBudgetError);
    ledger.set_evictor(nullptr);
}
